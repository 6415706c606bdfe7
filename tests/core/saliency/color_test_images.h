#ifndef FOVEA_TESTS_CORE_SALIENCY_COLOR_TEST_IMAGES_H_
#define FOVEA_TESTS_CORE_SALIENCY_COLOR_TEST_IMAGES_H_

// Synthetic images and checks shared by the colour-saliency tests.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace fovea::testing {

inline const cv::Vec3b kGrey(128, 128, 128);
inline const cv::Vec3b kRed(255, 0, 0);

// A red disc of radius 12 px on a grey 256 x 192 background, off centre so
// that a map peaking at the image centre fails.
inline cv::Mat RedDiscOnGrey(cv::Point center) {
  cv::Mat image(192, 256, CV_8UC3, cv::Scalar(kGrey));
  cv::circle(image, center, 12, cv::Scalar(kRed), cv::FILLED);
  return image;
}

// Black bars on grey, 6 x 4 of them at 640 x 480, all horizontal but one
// vertical at (kOddBarX, kOddBarY): the classic orientation pop-out
// (Treisman; shown by Itti 1998). Bar 60 x 12 px, about the size level 2-4
// filters see.
inline constexpr int kOddBarX = 476, kOddBarY = 184;
inline cv::Mat OddBarOut() {
  cv::Mat image(480, 640, CV_8UC3, cv::Scalar(kGrey));
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 4; ++j) {
      const cv::Point c(60 + i * 104, 70 + j * 114);
      const bool odd = c.x == kOddBarX && c.y == kOddBarY;
      const cv::Point half = odd ? cv::Point(6, 30) : cv::Point(30, 6);
      cv::rectangle(image, c - half, c + half, cv::Scalar(0, 0, 0), cv::FILLED);
    }
  }
  return image;
}

// A saliency map: CV_32FC1 of the given size with values in [0, 1].
inline void ExpectIsSaliencyMap(const cv::Mat& map, cv::Size size) {
  ASSERT_EQ(map.type(), CV_32FC1);
  ASSERT_EQ(map.size(), size);
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(map, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.0);
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_SALIENCY_COLOR_TEST_IMAGES_H_
