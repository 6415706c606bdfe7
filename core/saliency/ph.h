#ifndef FOVEA_CORE_SALIENCY_PH_H_
#define FOVEA_CORE_SALIENCY_PH_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/scene/table_scene.h"

namespace fovea {

struct PhOptions {
  // Preferred height as a fraction below the tallest point, [0, 1). 0 makes
  // the top of the tallest object most salient ("tall" objects, thesis
  // eq. 2.3); larger values prefer lower points.
  float top_offset_fraction = 0.0f;
};

absl::Status Validate(const PhOptions& options);

// Point height saliency (thesis eq. 2.3-2.4). With h the height of a
// candidate point above the plane, H the largest such height and
// h0 = (1 - top_offset_fraction) * H the preferred height:
//   s(h) = 1 - (1 - h / h0)^2, clamped to [0, 1]   (a parabola through
//   s(0) = 0 with its peak s(h0) = 1),
// then linearly normalised. 0 on the table, outside the hull and where
// there is no depth. An empty scene gives an all-zero map.
absl::StatusOr<cv::Mat> ComputePhSaliency(const TableScene& scene,
                                          const PhOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_PH_H_
