#ifndef FOVEA_CORE_SALIENCY_RSO_H_
#define FOVEA_CORE_SALIENCY_RSO_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea {

struct RsoOptions {
  // Preferred angle between a surface normal and the table normal,
  // degrees, [0, 90]. 0 favours surfaces parallel to the table (box tops,
  // thesis eq. 2.7).
  float preferred_angle_deg = 0.0f;
};

absl::Status Validate(const RsoOptions& options);

// Relative surface orientation saliency (thesis eq. 2.7). With theta the
// angle between a candidate point's normal and the support plane's normal
// and theta0 the preferred angle:
//   s = 1 - |theta - theta0| / 90 deg, clamped to [0, 1],
// so a box top scores ~1 and its vertical sides ~0. Linearly normalised;
// 0 off the candidates and where there is no normal.
absl::StatusOr<cv::Mat> ComputeRsoSaliency(const OrganizedCloud& cloud,
                                           const SupportPlane& plane,
                                           const TableScene& scene,
                                           const RsoOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_RSO_H_
