#include "core/saliency/sh.h"

#include <gtest/gtest.h>

#include "core/saliency/ph.h"
#include "tests/core/saliency/scene_fixture.h"

namespace fovea {
namespace {

// A tall box (0.20 m) and a short box (0.05 m) side by side.
synth::SynthScene TallAndShort() {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  synth::Primitive tall;
  tall.half_extents = {0.04f, 0.04f, 0.10f};
  tall.pose.translation() = Eigen::Vector3f(-0.12f, 0.05f, 0.10f);
  synth::Primitive low;
  low.half_extents = {0.06f, 0.05f, 0.025f};
  low.pose.translation() = Eigen::Vector3f(0.12f, -0.05f, 0.025f);
  low.rgb = {0.2f, 0.6f, 0.2f};
  spec.objects = {tall, low};
  synth::NoiseOptions noise;
  noise.enabled = false;
  return synth::RenderScene(spec, noise, 1);
}

TEST(ShSaliencyTest, ShortBoxWholeFootprintGetsTheBoxHeight) {
  testing::PreparedScene s = testing::Prepare(TallAndShort());
  absl::StatusOr<cv::Mat> map =
      ComputeShSaliency(s.cloud, s.plane, s.table, {});
  ASSERT_TRUE(map.ok());
  // Normalised by the tall box's 0.20 m: the short box should read 0.25
  // everywhere on its visible surface, sides included.
  const int short_label = s.truth.objects[1].label;
  int n = 0, near_height = 0;
  for (int v = 0; v < map->rows; ++v) {
    for (int u = 0; u < map->cols; ++u) {
      if (s.truth.frame.labels.at<int>(v, u) != short_label) continue;
      if (!s.table.candidate.at<uint8_t>(v, u)) continue;
      ++n;
      near_height += std::abs(map->at<float>(v, u) - 0.25f) < 0.03f;
    }
  }
  ASSERT_GT(n, 200);
  EXPECT_GT(near_height, n * 95 / 100) << near_height << " of " << n;
}

TEST(ShSaliencyTest, SidesGetTheTopHeightWherePointHeightDoesNot) {
  testing::PreparedScene s = testing::Prepare(TallAndShort());
  absl::StatusOr<cv::Mat> sh = ComputeShSaliency(s.cloud, s.plane, s.table, {});
  absl::StatusOr<cv::Mat> ph = ComputePhSaliency(s.table, {});
  ASSERT_TRUE(sh.ok() && ph.ok());
  const int tall_label = s.truth.objects[0].label;
  double sh_side = 0, ph_side = 0;
  int side = 0;
  for (int v = 0; v < sh->rows; ++v) {
    for (int u = 0; u < sh->cols; ++u) {
      if (s.truth.frame.labels.at<int>(v, u) != tall_label) continue;
      const float h = s.true_height.at<float>(v, u);
      if (h < 0.03f || h > 0.08f || !s.table.candidate.at<uint8_t>(v, u)) {
        continue;
      }
      sh_side += sh->at<float>(v, u);
      ph_side += ph->at<float>(v, u);
      ++side;
    }
  }
  ASSERT_GT(side, 100);
  EXPECT_GT(sh_side / side, 0.95);
  EXPECT_LT(ph_side / side, 0.7);
}

TEST(ShSaliencyTest, ValidateNamesTheField) {
  ShOptions options;
  options.radius = 0.0f;
  EXPECT_NE(Validate(options).message().find("sh.radius"), std::string::npos);
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

// Two candidate points 10 km apart on the plane z = 0: the grid would need
// 4e12 dense cells, so it must hash them, and each point still sees only
// itself.
TEST(ShSaliencyTest, ATableKilometresWideStaysBoundedAndCorrect) {
  OrganizedCloud cloud;
  cloud.xyz = cv::Mat(1, 3, CV_32FC3);
  cloud.xyz.at<cv::Vec3f>(0, 0) = {0.0f, 0.0f, 0.1f};
  cloud.xyz.at<cv::Vec3f>(0, 1) = {1e4f, 0.0f, 0.2f};
  cloud.xyz.at<cv::Vec3f>(0, 2) = {1e4f, 0.003f, 0.05f};  // 3 mm from #1
  cloud.normals = cv::Mat(1, 3, CV_32FC3, cv::Scalar::all(0));
  SupportPlane plane;  // z = 0, axes x and y
  plane.normal = Eigen::Vector3f::UnitZ();
  plane.axis_u = Eigen::Vector3f::UnitX();
  plane.axis_v = Eigen::Vector3f::UnitY();
  TableScene scene;
  scene.height = (cv::Mat_<float>(1, 3) << 0.1f, 0.2f, 0.05f);
  scene.candidate = cv::Mat(1, 3, CV_8UC1, cv::Scalar(255));
  scene.candidate_count = 3;
  absl::StatusOr<cv::Mat> map = ComputeShSaliency(cloud, plane, scene, {});
  ASSERT_TRUE(map.ok());
  EXPECT_FLOAT_EQ(map->at<float>(0, 0), 0.5f);
  EXPECT_FLOAT_EQ(map->at<float>(0, 1), 1.0f);
  EXPECT_FLOAT_EQ(map->at<float>(0, 2), 1.0f);  // takes its neighbour's
}

}  // namespace
}  // namespace fovea
