#include "core/saliency/sym3d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

// One primitive on the table, rendered at 160 x 120 (a Kinect frame at
// pyramid level 2), no noise, then taken to cloud, plane and table scene.
struct Rendered {
  synth::SynthScene truth;
  OrganizedCloud cloud;
  TableScene table;
};

Rendered Render(const synth::Primitive& object) {
  synth::SceneSpec spec;
  spec.width = 160;
  spec.height = 120;
  spec.intrinsics = {131.25, 131.25, 79.5, 59.5};
  spec.camera_pose = synth::LookAt({0.0f, -0.6f, 0.6f}, {0.0f, 0.0f, 0.0f});
  spec.objects = {object};
  synth::NoiseOptions noise;
  noise.enabled = false;
  Rendered r;
  r.truth = synth::RenderScene(spec, noise, 1);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(r.truth.frame.frame, {});
  EXPECT_TRUE(cloud.ok());
  r.cloud = *std::move(cloud);
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(r.cloud, {});
  EXPECT_TRUE(plane.ok()) << plane.status();
  TableSceneOptions table;
  table.min_object_height = 0.005f;
  r.table = PrepareTableScene(r.cloud, *plane, table);
  return r;
}

Sym3dOptions ObjectSizedKernel() {
  Sym3dOptions options;
  options.kernel_size = 13;
  return options;
}

TEST(Sym3dSaliencyTest, LyingCylinderPeaksOnItsAxisLine) {
  synth::Primitive cylinder;
  cylinder.shape = synth::Shape::kCylinder;
  cylinder.radius = 0.05f;
  cylinder.half_extents = {0.0f, 0.0f, 0.12f};
  // Axis along world x (across the image), resting on its side.
  cylinder.pose =
      Eigen::Translation3f(0.0f, 0.0f, 0.05f) *
      Eigen::AngleAxisf(static_cast<float>(M_PI / 2), Eigen::Vector3f::UnitY());
  const Rendered r = Render(cylinder);
  absl::StatusOr<cv::Mat> map =
      ComputeSym3dSaliency(r.cloud, r.table, ObjectSizedKernel());
  ASSERT_TRUE(map.ok()) << map.status();
  // In each column across the middle of the cylinder, the most symmetric
  // row lies near the middle of the cylinder's visible rows.
  int columns = 0, on_axis = 0;
  for (int u = 0; u < map->cols; ++u) {
    int top = -1, bottom = -1, best_row = -1;
    float best = 0.0f;
    for (int v = 0; v < map->rows; ++v) {
      if (r.table.candidate.at<uint8_t>(v, u) == 0) continue;
      if (top < 0) top = v;
      bottom = v;
      if (map->at<float>(v, u) > best) {
        best = map->at<float>(v, u);
        best_row = v;
      }
    }
    if (top < 0 || bottom - top < 10 || best_row < 0) continue;
    ++columns;
    const float middle = 0.5f * (top + bottom);
    on_axis += std::abs(best_row - middle) <= 0.2f * (bottom - top);
  }
  ASSERT_GT(columns, 20);
  EXPECT_GT(on_axis, columns * 8 / 10) << on_axis << " of " << columns;
}

TEST(Sym3dSaliencyTest, StandingConePeaksOnItsAxis) {
  // Fig. 2.4's cone: its axis projects to a vertical line through the
  // middle of its silhouette, and each row's most symmetric pixel is there.
  synth::Primitive cone;
  cone.shape = synth::Shape::kCone;
  cone.radius = 0.07f;
  cone.half_extents = {0.0f, 0.0f, 0.09f};
  cone.pose = Eigen::Isometry3f(Eigen::Translation3f(0.0f, 0.0f, 0.09f));
  const Rendered r = Render(cone);
  absl::StatusOr<cv::Mat> map =
      ComputeSym3dSaliency(r.cloud, r.table, ObjectSizedKernel());
  ASSERT_TRUE(map.ok()) << map.status();
  int rows = 0, on_axis = 0;
  for (int v = 0; v < map->rows; ++v) {
    int left = -1, right = -1, best_col = -1;
    float best = 0.0f;
    for (int u = 0; u < map->cols; ++u) {
      if (r.table.candidate.at<uint8_t>(v, u) == 0) continue;
      if (left < 0) left = u;
      right = u;
      if (map->at<float>(v, u) > best) {
        best = map->at<float>(v, u);
        best_col = u;
      }
    }
    if (left < 0 || right - left < 10 || best_col < 0) continue;
    ++rows;
    const float middle = 0.5f * (left + right);
    on_axis += std::abs(best_col - middle) <= 0.15f * (right - left);
  }
  ASSERT_GT(rows, 10);
  EXPECT_GT(on_axis, rows * 8 / 10) << on_axis << " of " << rows;
}

TEST(Sym3dSaliencyTest, SpherePeaksNearItsCentre) {
  synth::Primitive sphere;
  sphere.shape = synth::Shape::kSphere;
  sphere.radius = 0.07f;
  sphere.pose = Eigen::Isometry3f(Eigen::Translation3f(0.0f, 0.0f, 0.07f));
  const Rendered r = Render(sphere);
  absl::StatusOr<cv::Mat> map =
      ComputeSym3dSaliency(r.cloud, r.table, ObjectSizedKernel());
  ASSERT_TRUE(map.ok());
  cv::Point max_at;
  cv::minMaxLoc(*map, nullptr, nullptr, nullptr, &max_at);
  const cv::Moments m = cv::moments(r.table.candidate, true);
  const cv::Point2f centre(m.m10 / m.m00, m.m01 / m.m00);
  const float radius_px = std::sqrt(m.m00 / M_PI);
  EXPECT_LT(std::hypot(max_at.x - centre.x, max_at.y - centre.y),
            0.35f * radius_px);
}

TEST(Sym3dSaliencyTest, FlatBoxTopScoresAboutZeroAndItsEdgesHigh) {
  synth::Primitive box;
  box.shape = synth::Shape::kBox;
  box.half_extents = {0.08f, 0.08f, 0.04f};
  box.pose = Eigen::Translation3f(0.0f, 0.0f, 0.04f) *
             Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitZ());
  const Rendered r = Render(box);
  Sym3dOptions options;  // a small kernel: the top's middle is all flat
  options.kernel_size = 5;
  absl::StatusOr<cv::Mat> map = ComputeSym3dSaliency(r.cloud, r.table, options);
  ASSERT_TRUE(map.ok());
  // Pixels whose whole kernel sees one face (normals all alike) versus
  // pixels on an edge (normals of two faces).
  std::vector<float> flat, edge;
  for (int v = 3; v < map->rows - 3; ++v) {
    for (int u = 3; u < map->cols - 3; ++u) {
      if (!r.table.candidate.at<uint8_t>(v, u) || !r.cloud.HasNormal(u, v)) {
        continue;
      }
      float min_dot = 1.0f;
      int n = 0;
      const cv::Vec3f c = r.cloud.normals.at<cv::Vec3f>(v, u);
      for (int dv = -2; dv <= 2; ++dv) {
        for (int du = -2; du <= 2; ++du) {
          if (!r.cloud.HasNormal(u + du, v + dv)) continue;
          min_dot = std::min(
              min_dot, c.dot(r.cloud.normals.at<cv::Vec3f>(v + dv, u + du)));
          ++n;
        }
      }
      if (n < 20) continue;
      if (min_dot > 0.999f) flat.push_back(map->at<float>(v, u));
      if (min_dot < 0.6f) edge.push_back(map->at<float>(v, u));
    }
  }
  ASSERT_GT(flat.size(), 30u);
  ASSERT_GT(edge.size(), 10u);
  std::nth_element(flat.begin(), flat.begin() + flat.size() / 2, flat.end());
  std::nth_element(edge.begin(), edge.begin() + edge.size() / 2, edge.end());
  EXPECT_LT(flat[flat.size() / 2], 0.05f);
  EXPECT_GT(edge[edge.size() / 2], 0.3f);
}

TEST(Sym3dSaliencyTest, ValidateNamesTheField) {
  Sym3dOptions options;
  options.kernel_size = 4;
  EXPECT_NE(Validate(options).message().find("sym3d.kernel_size"),
            std::string::npos);
}

}  // namespace
}  // namespace fovea
