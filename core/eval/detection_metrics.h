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
  // Distinct objects hit by the first max(K, considered) points.
  int hits = 0;
  // hits / K. A point on the table or on nothing, a second point on an
  // already-hit object and a point that was not returned are all misses. 1
  // only for a perfect detector.
  double hit_ratio = 0.0;
  // Mean over the K slots of the first K points. A slot whose point hits a
  // new object scores (|p - c| - r_min) / (r_max - r_min), with c the 3D
  // centroid of the object's visible points and r_min, r_max the smallest
  // and largest distance of a visible point from c; every miss (as for
  // hit_ratio) scores 1. So DC is 0 only for a perfect detector: K points
  // on K distinct objects, each the visible point nearest its object's
  // centre. (The r_min offset is what lets a perfect detector reach 0: the
  // centroid of a curved object's visible surface lies inside it.)
  double distance_to_center = 1.0;
  // The thesis's ratio |p - c| / r_max (section 2.6.1), averaged over the
  // points among the first K that lie on an object, misses left out, as
  // Table 2.5 reports it; 1 when no point lies on an object.
  double distance_to_center_thesis = 1.0;
  // hit_ratio_at[N-1] = distinct objects hit among the first N points / N.
  std::array<double, kHitRatioAtMax> hit_ratio_at{};
  // Of all the points returned: those on an object already hit by an
  // earlier point (a second point in one object), and those on no object.
  int repeated_points = 0;
  int off_object_points = 0;
};

// Scores `points` (most salient first) against `labels` (CV_32SC1, OSD
// labels; objects are label / 10 for labels >= 20) and `xyz` (CV_32FC3 of
// the same size; NaN where there is no depth). A scene without objects gets
// objects = 0 and all ratios 0; callers leave such scenes out of averages.
// HR counts the first max(K, `considered`) points: the number a caller
// asked for (0: K, the thesis's HR); DC always the first K.
DetectionScore ScoreAttentionPoints(const std::vector<AttentionPoint>& points,
                                    const cv::Mat& labels, const cv::Mat& xyz,
                                    int considered = 0);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_DETECTION_METRICS_H_
