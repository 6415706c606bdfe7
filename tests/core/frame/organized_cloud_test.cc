#include "core/frame/organized_cloud.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

TEST(OrganizedCloudTest, BackProjectionInvertsThePinhole) {
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.5f);
  const OrganizedCloud cloud = BackProject(frame);
  const cv::Vec3f p = cloud.xyz.at<cv::Vec3f>(10, 150);
  EXPECT_NEAR(p[2], 1.5f, 1e-6f);
  EXPECT_NEAR(p[0], (150 - 79.5) * 1.5 / 130.0, 1e-5);
  EXPECT_NEAR(p[1], (10 - 59.5) * 1.5 / 130.0, 1e-5);
}

TEST(OrganizedCloudTest, TiltedPlaneNormalsAreThePlaneNormalTowardsCamera) {
  const Eigen::Vector3f n = Eigen::Vector3f(0.0f, -1.0f, -1.0f).normalized();
  RgbdFrame frame = testing::PlaneFrame(n, 0.9f);
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  int checked = 0;
  for (int v = 15; v < 105; v += 5) {
    for (int u = 15; u < 145; u += 5) {
      ASSERT_TRUE(cloud->HasNormal(u, v)) << u << "," << v;
      const cv::Vec3f m = cloud->normals.at<cv::Vec3f>(v, u);
      EXPECT_GT(n.dot(Eigen::Vector3f(m[0], m[1], m[2])), std::cos(1e-2f));
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(OrganizedCloudTest, NoDepthMeansNoPointAndNoNormal) {
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.0f);
  frame.depth(cv::Rect(60, 40, 20, 20))
      .setTo(std::numeric_limits<float>::quiet_NaN());
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok());
  EXPECT_FALSE(cloud->HasPoint(70, 50));
  EXPECT_FALSE(cloud->HasNormal(70, 50));
  EXPECT_TRUE(cloud->HasNormal(30, 50));
}

TEST(OrganizedCloudTest, DepthJumpLeavesNoNormalOnTheEdge) {
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.0f);
  frame.depth(cv::Rect(80, 0, 80, 120)).setTo(0.7f);
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok());
  EXPECT_FALSE(cloud->HasNormal(80, 60));
  EXPECT_FALSE(cloud->HasNormal(79, 60));
  EXPECT_TRUE(cloud->HasNormal(40, 60));
  EXPECT_TRUE(cloud->HasNormal(120, 60));
}

TEST(OrganizedCloudTest, ValidateNamesTheField) {
  NormalOptions options;
  options.max_half_window = 0;
  absl::Status s = Validate(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("normals.min_half_window"), std::string::npos);
}

}  // namespace
}  // namespace fovea
