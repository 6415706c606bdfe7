#include "core/scene/support_plane.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/table_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

TEST(SupportPlaneTest, FindsTheTableUnderABoxAndLeavesTheBoxOut) {
  const synth::SynthScene scene = testing::BoxOnTable({0.05f, 0.05f, 0.05f});
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  ASSERT_TRUE(cloud.ok());
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(*cloud, {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_GT(plane->normal.dot(scene.table_normal_camera), std::cos(0.01f));
  EXPECT_NEAR(plane->d, scene.table_d_camera, 0.003f);
  // Box pixels are not inliers; table pixels mostly are.
  int box = 0, box_in = 0, table = 0, table_in = 0;
  for (int v = 0; v < scene.frame.labels.rows; ++v) {
    for (int u = 0; u < scene.frame.labels.cols; ++u) {
      const int label = scene.frame.labels.at<int>(v, u);
      const bool in = plane->inliers.at<uint8_t>(v, u) != 0;
      if (label >= 20) {
        ++box;
        box_in += in;
      } else if (label == 1) {
        ++table;
        table_in += in;
      }
    }
  }
  ASSERT_GT(box, 100);
  EXPECT_LT(box_in, box / 50);
  EXPECT_GT(table_in, table * 9 / 10);
  EXPECT_EQ(plane->inlier_count, cv::countNonZero(plane->inliers));
}

TEST(SupportPlaneTest, TheBoxTopProjectsInsideTheHullAndFarAwayDoesNot) {
  const synth::SynthScene scene = testing::BoxOnTable({0.05f, 0.05f, 0.05f});
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  ASSERT_TRUE(cloud.ok());
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(*cloud, {});
  ASSERT_TRUE(plane.ok());
  int inside = 0, box_pixels = 0;
  for (int v = 0; v < cloud->height(); v += 3) {
    for (int u = 0; u < cloud->width(); u += 3) {
      if (scene.frame.labels.at<int>(v, u) < 20) continue;
      const cv::Vec3f p = cloud->xyz.at<cv::Vec3f>(v, u);
      ++box_pixels;
      inside += plane->ProjectsInsideHull({p[0], p[1], p[2]});
    }
  }
  EXPECT_EQ(inside, box_pixels);
  const Eigen::Vector3f far = plane->axis_u * 50.0f - plane->d * plane->normal;
  EXPECT_FALSE(plane->ProjectsInsideHull(far));
}

TEST(SupportPlaneTest, APlaneSeenHeadOnIsATableWithoutGravityAndAWallWithIt) {
  // The only plane faces the camera head-on. Without gravity nothing says
  // which way is up: a camera looking straight down at a table sees this,
  // so it is the support, its normal towards the camera. With gravity
  // along the image's y axis it is a wall, and there is no support.
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.2f);
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok());
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(*cloud, {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_GT(-plane->normal.z(), 0.99f);
  SupportHints hints;
  hints.gravity = Eigen::Vector3f(0.0f, 1.0f, 0.0f);
  EXPECT_EQ(FindSupportPlane(*cloud, {}, hints).status().code(),
            absl::StatusCode::kNotFound);
}

TEST(SupportPlaneTest, NoDepthIsNotFound) {
  RgbdFrame frame = testing::PlaneFrame({0.0f, -1.0f, -1.0f}, 1.0f);
  frame.depth.setTo(std::numeric_limits<float>::quiet_NaN());
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  ASSERT_TRUE(cloud.ok());
  EXPECT_EQ(FindSupportPlane(*cloud, {}).status().code(),
            absl::StatusCode::kNotFound);
}

TEST(SupportPlaneTest, ValidateNamesTheField) {
  SupportPlaneOptions options;
  options.inlier_distance = -1.0f;
  const absl::Status s = Validate(options);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("support_plane.inlier_distance"),
            std::string::npos);
}

TEST(TableSceneTest, BoxPixelsAreCandidatesAndTablePixelsAreNot) {
  const synth::SynthScene scene = testing::BoxOnTable({0.05f, 0.04f, 0.06f});
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  ASSERT_TRUE(cloud.ok());
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(*cloud, {});
  ASSERT_TRUE(plane.ok());
  const TableScene table = PrepareTableScene(*cloud, *plane, {});
  int box = 0, box_cand = 0, table_cand = 0;
  for (int v = 0; v < table.candidate.rows; ++v) {
    for (int u = 0; u < table.candidate.cols; ++u) {
      const int label = scene.frame.labels.at<int>(v, u);
      const bool cand = table.candidate.at<uint8_t>(v, u) != 0;
      if (label >= 20 && table.height.at<float>(v, u) > 0.015f) {
        ++box;
        box_cand += cand;
      }
      if (label == 1) table_cand += cand;
    }
  }
  EXPECT_GT(box, 100);
  EXPECT_EQ(box_cand, box);
  EXPECT_EQ(table_cand, 0);
  EXPECT_EQ(table.candidate_count, cv::countNonZero(table.candidate));
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

TEST(SupportPlaneTest, NonFinitePointsNeverProjectInsideTheHull) {
  SupportPlane plane;
  plane.hull = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  EXPECT_TRUE(plane.ProjectsInsideHull({0.0f, 0.0f, 0.5f}));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(plane.ProjectsInsideHull({nan, 0.0f, 0.5f}));
  EXPECT_FALSE(plane.ProjectsInsideHull({inf, 0.0f, 0.5f}));
  EXPECT_FALSE(plane.ProjectsInsideHull({0.0f, 0.0f, inf}));
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

TEST(SupportPlaneTest, MarginKeepsPointsNearTheHullEdgeOut) {
  SupportPlane plane;
  plane.hull = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};  // 2 m square
  EXPECT_TRUE(plane.ProjectsInsideHull({0.99f, 0.0f, 0.5f}));
  EXPECT_FALSE(plane.ProjectsInsideHull({0.99f, 0.0f, 0.5f}, 0.02f));
  EXPECT_TRUE(plane.ProjectsInsideHull({0.97f, 0.0f, 0.5f}, 0.02f));
}

}  // namespace
}  // namespace fovea
