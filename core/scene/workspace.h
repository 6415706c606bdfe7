#ifndef FOVEA_CORE_SCENE_WORKSPACE_H_
#define FOVEA_CORE_SCENE_WORKSPACE_H_

#include <Eigen/Core>
#include <optional>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/sensor_model.h"

namespace fovea {

// Where in the camera's view a request looks: nothing outside it is
// considered (no plane, no saliency, no object).
struct Workspace {
  // Depth range along the optical axis (camera z), metres. 0 means the
  // sensor model's: SensorModel::min_range_m and max_range_m (3 m for a
  // generic camera, 3.5 m for a Kinect v1), beyond which a table is too far
  // to work on and its depth too noisy to cut objects out of.
  float min_depth_m = 0.0f;
  float max_depth_m = 0.0f;
  // A box in the camera frame (x right, y down, z forward), metres: only
  // points inside it (min <= p <= max on every axis) are kept.
  struct Box {
    Eigen::Vector3f min = Eigen::Vector3f::Zero();
    Eigen::Vector3f max = Eigen::Vector3f::Zero();
  };
  std::optional<Box> box;
};

// INVALID_ARGUMENT naming the field (workspace.min_depth_m, ..., and
// workspace.box for an empty or non-finite box): depths finite and >= 0,
// max above min when both are set.
absl::Status Validate(const Workspace& workspace);

// The depth range actually used: the workspace's, or the sensor's where 0.
struct DepthRange {
  float min_m = 0.0f;
  float max_m = 0.0f;
};
DepthRange EffectiveDepthRange(const Workspace& workspace,
                               const SensorModel& sensor);

// Sets xyz to NaN for the points outside the workspace (depth range and
// box); returns how many were removed. Call before estimating normals.
int ApplyWorkspace(const Workspace& workspace, const SensorModel& sensor,
                   OrganizedCloud& cloud);

}  // namespace fovea

#endif  // FOVEA_CORE_SCENE_WORKSPACE_H_
