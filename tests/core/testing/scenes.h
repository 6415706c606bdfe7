#ifndef FOVEA_TESTS_CORE_TESTING_SCENES_H_
#define FOVEA_TESTS_CORE_TESTING_SCENES_H_

// Small analytic scenes for core tests.

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/frame/rgbd_frame.h"
#include "core/synth/synth_scene.h"

namespace fovea::testing {

// Depth image of the plane n . p + d = 0 seen through `intrinsics`
// (NaN where a ray misses it or hits behind the camera).
inline RgbdFrame PlaneFrame(const Eigen::Vector3f& n, float d, int width = 160,
                            int height = 120,
                            Intrinsics intrinsics = {130.0, 130.0, 79.5,
                                                     59.5}) {
  RgbdFrame frame;
  frame.intrinsics = intrinsics;
  frame.color = cv::Mat(height, width, CV_8UC3, cv::Scalar(128, 128, 128));
  frame.depth = cv::Mat(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3f ray((u - intrinsics.cx) / intrinsics.fx,
                                (v - intrinsics.cy) / intrinsics.fy, 1.0f);
      const float denom = n.dot(ray);
      const float z = std::abs(denom) > 1e-9f ? -d / denom : -1.0f;
      frame.depth.at<float>(v, u) =
          z > 0.0f ? z : std::numeric_limits<float>::quiet_NaN();
    }
  }
  return frame;
}

// A box of the given size standing on the table centre, camera 0.75 m up
// and 0.75 m back looking at it; no noise.
inline synth::SynthScene BoxOnTable(const Eigen::Vector3f& half_extents,
                                    const Eigen::Vector2f& at = {0.0f, 0.0f}) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  synth::Primitive box;
  box.shape = synth::Shape::kBox;
  box.half_extents = half_extents;
  box.pose.translation() = Eigen::Vector3f(at.x(), at.y(), half_extents.z());
  spec.objects.push_back(box);
  synth::NoiseOptions noise;
  noise.enabled = false;
  return synth::RenderScene(spec, noise, 1);
}

// Two boxes touching side by side on the table: a red one 8 x 6 x 10 cm on
// the left (label 20) and a blue one 8 x 6 x 6 cm on the right (label 30),
// set back 2 cm so that their fronts are not one plane (planar patches
// would merge coplanar faces: they see geometry only).
// Camera as in BoxOnTable; no noise. The blue top lies below the red top, so
// the two together are not convex.
// With `gap` > 0 the blue box stands that many metres further right.
// `camera` moves the camera (world frame, looking at the origin): the default
// lies in the boxes' contact plane x = 0, which it sees edge-on, so the
// visible surfaces of touching boxes are 2 cm apart (their fronts); from
// x > 0 it sees the red box's right face rise above the blue top.
inline synth::SynthScene TwoBoxesOnTable(
    float gap = 0.0f,
    const Eigen::Vector3f& camera = Eigen::Vector3f(0.0f, -0.75f, 0.75f)) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt(camera, {0.0f, 0.0f, 0.0f});
  for (const float side : {-1.0f, 1.0f}) {
    synth::Primitive box;
    box.shape = synth::Shape::kBox;
    box.half_extents = {0.04f, 0.04f, side < 0.0f ? 0.05f : 0.03f};
    box.pose.translation() =
        Eigen::Vector3f(side * 0.04f + (side < 0.0f ? 0.0f : gap),
                        side < 0.0f ? 0.0f : 0.02f, box.half_extents.z());
    box.rgb = side < 0.0f ? Eigen::Vector3f(0.9f, 0.2f, 0.1f)
                          : Eigen::Vector3f(0.1f, 0.3f, 0.9f);
    spec.objects.push_back(box);
  }
  synth::NoiseOptions noise;
  noise.enabled = false;
  return synth::RenderScene(spec, noise, 1);
}

// The pixel of `label` farthest from every other label (its visible
// centre); (-1, -1) when the label is absent.
inline cv::Point CentreOfLabel(const cv::Mat& labels, int label) {
  cv::Mat inside = labels == label;
  if (cv::countNonZero(inside) == 0) return {-1, -1};
  cv::Mat distance;
  cv::distanceTransform(inside, distance, cv::DIST_L2, 3);
  cv::Point best;
  cv::minMaxLoc(distance, nullptr, nullptr, nullptr, &best);
  return best;
}

// Height of each pixel above the scene's table (NaN without depth).
inline cv::Mat HeightAboveTable(const synth::SynthScene& scene) {
  const RgbdFrame& f = scene.frame.frame;
  cv::Mat height(f.height(), f.width(), CV_32FC1);
  for (int v = 0; v < f.height(); ++v) {
    for (int u = 0; u < f.width(); ++u) {
      const float z = f.depth.at<float>(v, u);
      const Eigen::Vector3f p((u - f.intrinsics.cx) * z / f.intrinsics.fx,
                              (v - f.intrinsics.cy) * z / f.intrinsics.fy, z);
      height.at<float>(v, u) =
          scene.table_normal_camera.dot(p) + scene.table_d_camera;
    }
  }
  return height;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_TESTING_SCENES_H_
