#ifndef FOVEA_CORE_SALIENCY_SH_H_
#define FOVEA_CORE_SALIENCY_SH_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea {

struct ShOptions {
  // Neighbourhood radius in plane coordinates, metres (thesis eq. 2.5: 5 mm).
  float radius = 0.005f;
};

absl::Status Validate(const ShOptions& options);

// Surface height saliency (thesis eq. 2.5-2.6): every candidate point takes
// the largest height of the candidate points whose projections onto the
// support plane lie within `radius` of its own projection, so the whole
// visible surface of an object (its sides too) gets the height of the
// object's top above that spot. Neighbours are found with a uniform grid
// of cell size `radius` in plane coordinates (O(n), not all pairs).
// Linearly normalised; 0 off the candidates.
absl::StatusOr<cv::Mat> ComputeShSaliency(const OrganizedCloud& cloud,
                                          const SupportPlane& plane,
                                          const TableScene& scene,
                                          const ShOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_SH_H_
