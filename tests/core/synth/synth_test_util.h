#ifndef FOVEA_TESTS_CORE_SYNTH_SYNTH_TEST_UTIL_H_
#define FOVEA_TESTS_CORE_SYNTH_SYNTH_TEST_UTIL_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The pixel `world` projects to in `spec`'s camera (no distortion).
inline Eigen::Vector2f Project(const SceneSpec& spec,
                               const Eigen::Vector3f& world) {
  const Eigen::Vector3f c = spec.camera_pose.inverse() * world;
  return {static_cast<float>(spec.intrinsics.fx * c.x() / c.z() +
                             spec.intrinsics.cx),
          static_cast<float>(spec.intrinsics.fy * c.y() / c.z() +
                             spec.intrinsics.cy)};
}

}  // namespace fovea::synth

#endif  // FOVEA_TESTS_CORE_SYNTH_SYNTH_TEST_UTIL_H_
