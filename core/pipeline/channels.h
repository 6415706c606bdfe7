#ifndef FOVEA_CORE_PIPELINE_CHANNELS_H_
#define FOVEA_CORE_PIPELINE_CHANNELS_H_

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/saliency_registry.h"
#include "core/pyramid/cloud_pyramid.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea {

// Whether the channels of `options` read the cloud pyramid (a geometric
// operator with a feature pyramid, or on a coarser level without one).
bool UsesCloudPyramid(const DetectOptions& options);

// The levels the channels of `options` read: options.cloud_pyramid, but
// without a feature pyramid only down to the operators' level.
CloudPyramidOptions CloudPyramidLevels(const DetectOptions& options);

// Computes saliency channels for one frame. Keeps the state the channels
// share: the Gaussian cloud pyramid and each level's table scene, built on
// first use (a frame with only level-0 channels never builds them).
class ChannelComputer {
 public:
  // `cloud`, `plane` and `table` are level 0 and must outlive this object;
  // so must `pyramid` when given: BuildCloudPyramid(cloud,
  // CloudPyramidLevels(options)), built beforehand (else built on first
  // use).
  ChannelComputer(const OrganizedCloud& cloud, const SupportPlane& plane,
                  const TableScene& table, const DetectOptions& options,
                  const CloudPyramid* pyramid = nullptr);

  // The channel's map, CV_32FC1 of level 0's size, in [0, 1]:
  //  - pyramid NONE: the operator on one level (level 0; SYM3D on
  //    options.sym3d_level, resampled to level 0), normalised with
  //    options.normalization (eq. 2.37-2.39);
  //  - pyramid SIMPLE / ITTI: the operator's conspicuity map over the cloud
  //    pyramid (eq. 2.35-2.41);
  // either way zero off level 0's candidate points. Colour and top-down
  // operators work on the whole colour image (they are multi-scale
  // themselves; the pyramid option does not apply), normalised with
  // options.normalization.
  absl::StatusOr<cv::Mat> Compute(SaliencyOp op);

 private:
  absl::StatusOr<const CloudPyramid*> Pyramid();
  absl::StatusOr<const TableScene*> TableAt(int level);
  // The registry's row of `op` (saliency_registry.h).
  static const SaliencyOperator& Row(SaliencyOp op);
  // A kGeometry operator on pyramid level `level`, at that level's size.
  absl::StatusOr<cv::Mat> OperatorAt(SaliencyOp op, int level);
  // `map` (level 0) zeroed off level 0's candidates, where resampling and
  // pyramids smear it (only points on the table get saliency), then
  // linearly normalised.
  cv::Mat OnCandidates(cv::Mat map) const;

  const OrganizedCloud& cloud_;
  const SupportPlane& plane_;
  const TableScene& table_;
  const DetectOptions& options_;
  const CloudPyramid* prebuilt_;  // not owned; null: none
  std::optional<CloudPyramid> pyramid_;
  std::vector<std::optional<TableScene>> tables_;  // per level, level 0 unused
};

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_CHANNELS_H_
