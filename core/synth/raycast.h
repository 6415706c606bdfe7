#ifndef FOVEA_CORE_SYNTH_RAYCAST_H_
#define FOVEA_CORE_SYNTH_RAYCAST_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>

#include "core/synth/synth_scene.h"

namespace fovea::synth {

// Exact ray casting of the primitives of synth_scene.h. A ray is
// origin + t * direction; `direction` need not be unit length, and t is in
// units of its length (so with a camera-frame direction (x, y, 1), t is the
// camera depth z).

struct RayHit {
  float t = 0.0f;
  // Unit outward normal of the surface at the hit, in the ray's frame.
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
};

// The nearest intersection of a world-frame ray with the closed surface of
// `primitive` (box faces; cylinder side and caps; sphere; cone side and base
// disc) with t in (t_min, t_max), or nullopt.
std::optional<RayHit> IntersectPrimitive(const Primitive& primitive,
                                         const Eigen::Vector3f& origin,
                                         const Eigen::Vector3f& direction,
                                         float t_min, float t_max);

// The nearest intersection with the table rectangle (z = 0, |x| <= hx,
// |y| <= hy) with t in (t_min, t_max), or nullopt. Normal +z.
std::optional<RayHit> IntersectTable(const Eigen::Vector2f& table_half_size,
                                     const Eigen::Vector3f& origin,
                                     const Eigen::Vector3f& direction,
                                     float t_min, float t_max);

// One ray per pixel centre through spec.intrinsics from spec.camera_pose,
// nearest hit wins (table, objects, background parts and object parts).
struct RaycastImage {
  cv::Mat depth;  // CV_32FC1, camera z, metres; NaN where nothing is hit
  // CV_32SC1: -1 nothing, 0 table, k + 1 spec.objects[k],
  // objects.size() + 1 + j spec.background[j],
  // objects.size() + background.size() + 1 + i spec.object_parts[i].
  cv::Mat hit;
  cv::Mat normal;  // CV_32FC3, world-frame unit normal facing the camera
};
RaycastImage RaycastScene(const SceneSpec& spec);

// Pixels of each object (its parts included) in a reduced ray cast of
// `spec` without its background: half of a 640-pixel-wide frame, at most
// `max_width` columns whatever the frame's resolution (the room around the
// table never stands between the camera and the table's objects). What
// the scene generators check visibility with while placing objects.
std::vector<int> ReducedObjectPixelCounts(SceneSpec spec, int max_width);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_RAYCAST_H_
