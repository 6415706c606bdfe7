#ifndef FOVEA_CORE_ATTENTION_TJ_H_
#define FOVEA_CORE_ATTENTION_TJ_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/attention/attention_point.h"

namespace fovea {

// Which junction of a skeleton with several is the component's point (the
// thesis takes "a junction").
enum class TjJunction {
  // The junction nearest the component's centroid (unweighted, pixels):
  // on a component that covers an object, the place where the skeleton's
  // branches from the object's parts meet. On the 45 OSD learn scenes
  // (SYM3D, ITTI pyramid) it lowers DC from 0.27 to 0.18 at equal HR.
  kCentral,
  // The junction with the highest map saliency; on SYM3D maps that is a
  // box's top edge or a rim.
  kMostSalient,
};

// Order of the points.
enum class TjRanking {
  // Total saliency of the component (mean x area): a large salient object
  // before a sliver. The pieces an occluder cuts out of an object are small,
  // so they no longer come before the occluder (learn scenes: HR 0.84 ->
  // 0.91 with SYM3D single level).
  kTotalSaliency,
  // Mean saliency of the component (thesis sections 2.5.3 and 3.2.1).
  kMeanSaliency,
};

struct TjOptions {
  // theta_sal: components whose mean saliency is below this fraction of the
  // map's global maximum are dropped (thesis sections 2.5.3 and 3.2.1:
  // 10 %); range [0, 1].
  float min_mean_fraction = 0.1f;
  // Components are taken of the pixels at or above this fraction of the
  // map's global maximum, [0, 1). 0 is the thesis's "map above zero"; a
  // smoothed map is above zero between touching objects too, which joins
  // them into one component and one point.
  float support_fraction = 0.0f;
  TjJunction junction = TjJunction::kCentral;
  TjRanking ranking = TjRanking::kTotalSaliency;
  // Components of fewer pixels give no point. 0 keeps every component
  // (the thesis); Detect sets it from DetectOptions::min_region_pixels.
  int min_component_pixels = 0;
};

absl::Status Validate(const TjOptions& options);

// T-junction attention points (thesis sections 2.5.3 and 3.2.1).
//
// `map` is CV_32FC1; pixels with saliency > 0 are foreground (NaN is
// background). Steps:
//  1. 8-connected components of the foreground.
//  2. Drop components whose mean saliency is below
//     theta_sal = min_mean_fraction * (global maximum of the map), and
//     those smaller than min_component_pixels.
//  3. Skeleton of each kept component (see ThinToSkeleton).
//  4. The component's point is a junction of its skeleton, a skeleton pixel
//     with SkeletonBranchCount >= 3, chosen by `options.junction`; ties go
//     to the first in row-major order (kMostSalient: then to the one nearest
//     the saliency-weighted centroid). Without a junction,
//     the point is the middle of the skeleton's longest path: the path
//     between the two ends of a double breadth-first search (8-connected
//     steps), and the pixel on it whose Euclidean arc length from one end
//     is nearest half the path's length. A one-pixel skeleton gives that
//     pixel; a loop gives a pixel on the loop.
//  5. Points are ranked by `options.ranking`, highest first (ties: the
//     component whose first pixel comes first in row-major order), and cut
//     to `max_points`. A point's saliency is its component's mean
//     (kMeanSaliency) or its component's total saliency divided by the
//     largest kept component's area (kTotalSaliency); either way in [0, 1]
//     and non-increasing down the list.
// Work is one pass over the map plus, per kept component, work bounded by
// its area (thinning visits only the component's border pixels).
// An all-zero map gives no points.
// Errors: empty map or wrong type, an infinite map value, max_points < 0,
// invalid options.
absl::StatusOr<std::vector<AttentionPoint>> ExtractTjPoints(
    const cv::Mat& map, int max_points, const TjOptions& options);

// Skeleton of a binary image, as ExtractTjPoints makes it (exposed for
// tests and pictures). `mask` is CV_8UC1, non-zero = foreground. Each
// 8-connected component is thinned by Guo & Hall's parallel algorithm A1
// (Guo & Hall 1989, "Parallel thinning with two-subiteration algorithms"),
// which keeps every component connected (never deletes one whole) and keeps
// holes as loops, then staircase corners are removed one pixel at a time: a
// pixel with two perpendicular 4-neighbours set whose opposite two
// 4-neighbours and the diagonal between those are clear is redundant in
// 8-connectivity. The result is a one-pixel-wide, 8-connected skeleton per
// component. Returns CV_8UC1, 255 on the skeleton, 0 elsewhere.
// Errors: empty mask or wrong type.
absl::StatusOr<cv::Mat> ThinToSkeleton(const cv::Mat& mask);

// Number of skeleton branches leaving pixel (u, v) of `skeleton` (CV_8UC1,
// non-zero = skeleton; pixels outside the image count as 0): the number of
// 0 -> 1 transitions going once round its eight neighbours N, NE, E, SE, S,
// SW, W, NW, N (Rutovitz's crossing number). 1 at the end of a line, 2 on
// a line (also on a diagonal staircase, where a naive count of neighbours
// gives 3 or 4), >= 3 at a junction. Returns 0 for a pixel outside the
// image.
int SkeletonBranchCount(const cv::Mat& skeleton, int u, int v);

}  // namespace fovea

#endif  // FOVEA_CORE_ATTENTION_TJ_H_
