#ifndef FOVEA_CORE_EVAL_DETECTION_METRICS_H_
#define FOVEA_CORE_EVAL_DETECTION_METRICS_H_

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "core/attention/attention_point.h"

namespace fovea {

inline constexpr int kHitRatioAtMax = 10;

// Detection quality of one scene's attention points (thesis section 2.6.1).
struct DetectionScore {
  int objects = 0;  // K: ground-truth objects (label / 10) in the scene
  int hits = 0;     // distinct objects hit by the first K points
  // Distinct objects hit among the first K points / K. A point on the table
  // or on nothing, a second point on an already-hit object and a point that
  // was not returned are all misses. 1 only for a perfect detector.
  double hit_ratio = 0.0;
  // Mean, over the first K points that lie on an object, of
  //   (|p - c| - r_min) / (r_max - r_min)
  // with c the 3D centroid of the object's visible points and r_min, r_max
  // the smallest and largest distance of a visible point from c. 0 only
  // when every point is the visible point nearest its object's centre;
  // 1 when no point lies on an object (silence does not score well).
  double distance_to_center = 1.0;
  // The thesis's ratio |p - c| / r_max over the same points, for comparison
  // with Table 2.5 (its best value is above 0 for curved objects).
  double distance_to_center_thesis = 1.0;
  // hit_ratio_at[N-1] = distinct objects hit among the first N points / N.
  std::array<double, kHitRatioAtMax> hit_ratio_at{};
};

// Scores `points` (most salient first) against `labels` (CV_32SC1, OSD
// labels; objects are label / 10 for labels >= 20) and `xyz` (CV_32FC3 of
// the same size; NaN where there is no depth). A scene without objects gets
// objects = 0 and all ratios 0; callers leave such scenes out of averages.
DetectionScore ScoreAttentionPoints(const std::vector<AttentionPoint>& points,
                                    const cv::Mat& labels, const cv::Mat& xyz);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_DETECTION_METRICS_H_
