#ifndef FOVEA_TESTS_CORE_ATTENTION_TEST_MAPS_H_
#define FOVEA_TESTS_CORE_ATTENTION_TEST_MAPS_H_

// Saliency maps for the attention-point extractor tests.

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

namespace fovea::testing {

// Raises `map` (CV_32FC1) to a Gaussian blob of the given centre, spread
// (pixels) and peak wherever the blob is higher. With `cut` > 0, the blob
// is 0 where it falls below `cut` of its peak (a normalised saliency map is
// zero away from objects).
inline void AddBlob(cv::Mat& map, float cu, float cv, float sigma, float peak,
                    float cut = 0.0f) {
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) {
      const float d2 = (u - cu) * (u - cu) + (v - cv) * (v - cv);
      const float s = std::exp(-d2 / (2 * sigma * sigma));
      if (cut > 0.0f && !(s > cut)) continue;
      map.at<float>(v, u) = std::max(map.at<float>(v, u), peak * s);
    }
  }
}

// A 640x480 map like a table scene's: four Gaussian blobs and two
// rectangles.
inline cv::Mat SceneLikeMap(float blob_cut = 0.0f) {
  cv::Mat map(480, 640, CV_32FC1, cv::Scalar(0));
  AddBlob(map, 120, 140, 25, 0.9f, blob_cut);
  AddBlob(map, 330, 260, 35, 1.0f, blob_cut);
  AddBlob(map, 520, 120, 20, 0.6f, blob_cut);
  AddBlob(map, 200, 380, 30, 0.7f, blob_cut);
  map(cv::Rect(420, 300, 120, 80)).setTo(0.5f);
  map(cv::Rect(40, 20, 60, 30)).setTo(0.35f);
  return map;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_ATTENTION_TEST_MAPS_H_
