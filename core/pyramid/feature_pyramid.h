#ifndef FOVEA_CORE_PYRAMID_FEATURE_PYRAMID_H_
#define FOVEA_CORE_PYRAMID_FEATURE_PYRAMID_H_

#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/pyramid/cloud_pyramid.h"
#include "core/pyramid/normalization.h"

namespace fovea {

// Feature pyramids and conspicuity maps (thesis section 2.4, eq. 2.35-2.41).

// A saliency operator run on one pyramid level: returns a CV_32FC1 map of
// the level's size (cloud.height() x cloud.width()), values finite and
// >= 0 (0 = not salient). An error status stops BuildConspicuityMap and is
// returned as is.
using LevelFeature = std::function<absl::StatusOr<cv::Mat>(
    int level, const OrganizedCloud& cloud)>;

enum class FeaturePyramidKind {
  kSimple,  // eq. 2.35: F_l = S(P_l)
  kItti,    // eq. 2.36: F_{c,s} = |F_c - F_s|, s = c + d
};

// How the feature maps of several scales become one conspicuity map.
enum class ScaleCombination {
  kSum,  // eq. 2.40: pixel-wise sum
  kMax,  // eq. 2.41: pixel-wise maximum
};

struct FeaturePyramidOptions {
  FeaturePyramidKind kind = FeaturePyramidKind::kSimple;
  // Across-scale combination (eq. 2.40 / 2.41).
  ScaleCombination combination = ScaleCombination::kSum;
  // Applied to every feature map before the combination (eq. 2.37-2.39).
  MapNormalization normalization = MapNormalization::kLin;
  NormalizationOptions normalization_options;
  // Level at which the feature maps are combined (Itti, Koch & Niebur
  // 1998: scale 4). [0, 15]; when the pyramid is shallower, its deepest
  // level is used.
  int output_level = 4;
  // SIMPLE: the levels whose maps are combined (eq. 2.35: all L levels).
  // Each >= 0; levels the pyramid lacks are skipped.
  std::vector<int> simple_levels = {0, 1, 2, 3, 4, 5, 6, 7};
  // ITTI: centre levels c (eq. 2.36: {2, 3, 4}). Each >= 0.
  std::vector<int> itti_centres = {2, 3, 4};
  // ITTI: surround offsets d, surround level s = c + d (eq. 2.36: {3, 4}).
  // Each >= 1. A pair whose surround level the pyramid lacks is skipped
  // (with the default 8 levels, 0..7, that is (c, s) = (4, 8)).
  std::vector<int> itti_deltas = {3, 4};
};

// OK, or INVALID_ARGUMENT naming the field that breaks its range (the
// level lists must not be empty).
absl::Status Validate(const FeaturePyramidOptions& options);

// One feature map that went into a conspicuity map.
struct FeatureScale {
  int centre = 0;     // SIMPLE: the level l; ITTI: c
  int surround = -1;  // ITTI: s = c + d; SIMPLE: -1
};

struct Conspicuity {
  cv::Mat map;           // CV_32FC1, level 0's size, [0, 1] (eq. 2.37)
  int output_level = 0;  // where the scales were combined
  std::vector<FeatureScale> scales;  // the maps combined, in option order
};

// Moves a map between pyramid levels along the pyramid's level sizes:
// repeated cv::pyrDown towards coarser levels, cv::pyrUp towards finer
// ones. Both keep the pyramid's geometry (coarse pixel u sits on fine
// pixel 2u) and its ceil(n / 2) sizes; pyrUp interpolates with the same
// 5-tap kernel (a smooth, not exact, interpolation). Input: CV_32FC1 of
// level `from`'s size. INVALID_ARGUMENT for levels outside the pyramid or
// a map of the wrong size or type.
absl::StatusOr<cv::Mat> ResampleBetweenLevels(const cv::Mat& map, int from,
                                              int to,
                                              const CloudPyramid& pyramid);

// Builds the conspicuity map of one saliency channel:
//  1. feature maps, `feature` run once per level that is needed:
//       SIMPLE: F_l = feature(l, P_l) for l in simple_levels present in
//               the pyramid (eq. 2.35);
//       ITTI:   F_{c,s} = |F_c - up(F_s)| for each c in itti_centres and
//               d in itti_deltas with s = c + d present in the pyramid,
//               F_s moved to level c by ResampleBetweenLevels (eq. 2.36);
//  2. each map normalised with NormalizeMap(options.normalization);
//  3. all moved to the output level (min(output_level, deepest level))
//     and combined pixel-wise by SUM (eq. 2.40) or MAX (eq. 2.41);
//  4. moved to level 0 and linearly normalised (eq. 2.37).
// Skip rule: a level (SIMPLE) or a centre-surround pair (ITTI) is used
// only if every level it needs exists in the pyramid; the others are
// skipped silently and `scales` lists what was used.
// Errors: INVALID_ARGUMENT from Validate, for an empty pyramid, or for a
// feature map of the wrong size or type (naming the level); FAILED_
// PRECONDITION when no level or pair is left (the pyramid is too
// shallow, e.g. ITTI on fewer than 6 levels); the feature's own errors;
// NormalizeMap's errors. An all-zero feature gives an all-zero map.
absl::StatusOr<Conspicuity> BuildConspicuityMap(
    const CloudPyramid& pyramid, const LevelFeature& feature,
    const FeaturePyramidOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_PYRAMID_FEATURE_PYRAMID_H_
