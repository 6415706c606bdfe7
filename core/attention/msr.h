#ifndef FOVEA_CORE_ATTENTION_MSR_H_
#define FOVEA_CORE_ATTENTION_MSR_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/attention/attention_point.h"

namespace fovea {

struct MsrOptions {
  // A neighbour joins the region when its saliency is at least
  // (1 - region_tolerance) times the seed's (thesis section 2.5.2: 25 %).
  float region_tolerance = 0.25f;
  // Stop when the largest remaining saliency is below this fraction of the
  // map's global maximum (nothing left worth attending).
  float min_relative_saliency = 0.05f;
  // Regions smaller than this are inhibited but yield no point (isolated
  // noisy pixels), pixels.
  int min_region_pixels = 20;
  // Also inhibit the slope around the region: neighbours whose saliency
  // does not rise above the pixel they are reached from. The thesis
  // inhibits the region alone, which leaves the lower rim of a salient
  // object (below the tolerance) to seed further points on the same
  // object. Off reproduces the thesis exactly.
  bool inhibit_slope = true;
};

absl::Status Validate(const MsrOptions& options);

// Most Salient Region (thesis section 2.5.2). Repeats up to `max_points`
// times: seed at the global maximum of the remaining map; grow an
// 8-connected region from it over pixels whose saliency is within
// `region_tolerance` of the seed's; the attention point is the region
// pixel nearest to the region's saliency-weighted centroid (so it lies on
// the region even when the region is not convex); inhibit the region
// (set it to 0). Points come most salient first, saliency = seed value.
// `map` is CV_32FC1; fewer points come back when the map runs out.
absl::StatusOr<std::vector<AttentionPoint>> ExtractMsrPoints(
    const cv::Mat& map, int max_points, const MsrOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_ATTENTION_MSR_H_
