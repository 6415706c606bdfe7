#include "core/pyramid/cloud_pyramid.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "core/frame/organized_cloud.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A plane seen by a camera, with the analytic normal (towards the camera)
// at every pixel that has a point.
OrganizedCloud PlaneCloud(const Eigen::Vector3f& n, float d, int width,
                          int height) {
  OrganizedCloud cloud = BackProject(testing::PlaneFrame(n, d, width, height));
  cloud.normals = cv::Mat(height, width, CV_32FC3, cv::Scalar::all(kNaN));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (cloud.HasPoint(u, v)) {
        cloud.normals.at<cv::Vec3f>(v, u) = {n.x(), n.y(), n.z()};
      }
    }
  }
  return cloud;
}

// A fronto-parallel depth image with the given depth per column.
OrganizedCloud ColumnsCloud(const std::vector<float>& z_per_column,
                            int height) {
  RgbdFrame frame;
  frame.intrinsics = {100.0, 100.0, 20.0, 10.0};
  const int width = static_cast<int>(z_per_column.size());
  frame.color = cv::Mat(height, width, CV_8UC3, cv::Scalar(10, 20, 30));
  frame.depth = cv::Mat(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      frame.depth.at<float>(v, u) = z_per_column[u];
    }
  }
  return BackProject(frame);
}

TEST(CloudPyramidTest, TiltedPlaneStaysOnThePlaneWithItsNormalAtEveryLevel) {
  const Eigen::Vector3f n = Eigen::Vector3f(0.2f, -0.6f, -1.0f).normalized();
  const float d = 1.0f;
  absl::StatusOr<CloudPyramid> pyramid =
      BuildCloudPyramid(PlaneCloud(n, d, 160, 120), {});
  ASSERT_TRUE(pyramid.ok()) << pyramid.status();
  ASSERT_EQ(pyramid->size(), 6);  // 160x120 ... 5x4; 3x2 < min_size 4
  for (int l = 0; l < pyramid->size(); ++l) {
    const OrganizedCloud& level = pyramid->levels[l];
    int points = 0;
    for (int v = 0; v < level.height(); ++v) {
      for (int u = 0; u < level.width(); ++u) {
        ASSERT_TRUE(level.HasPoint(u, v)) << "level " << l;
        const cv::Vec3f p = level.xyz.at<cv::Vec3f>(v, u);
        const cv::Vec3f m = level.normals.at<cv::Vec3f>(v, u);
        EXPECT_NEAR(n.dot(Eigen::Vector3f(p[0], p[1], p[2])) + d, 0.0f, 1e-5f)
            << "level " << l << " at " << u << "," << v;
        EXPECT_NEAR(m[0], n.x(), 1e-5f);
        EXPECT_NEAR(m[1], n.y(), 1e-5f);
        EXPECT_NEAR(m[2], n.z(), 1e-5f);
        ++points;
      }
    }
    EXPECT_EQ(points, level.width() * level.height());
  }
}

TEST(CloudPyramidTest, LevelPointsProjectOntoTheirPixelWithLevelIntrinsics) {
  // Fronto-parallel plane: the filtered point at coarse pixel u' is the
  // point of fine pixel 2u', so it must project to u' with cx' = cx / 2.
  // (cx - 0.5) / 2 would put it a quarter pixel off at level 1.
  const Eigen::Vector3f n(0.0f, 0.0f, -1.0f);
  absl::StatusOr<CloudPyramid> pyramid =
      BuildCloudPyramid(PlaneCloud(n, 1.5f, 160, 120), {});
  ASSERT_TRUE(pyramid.ok()) << pyramid.status();
  for (int l = 1; l < pyramid->size(); ++l) {
    const OrganizedCloud& level = pyramid->levels[l];
    const Intrinsics& k = level.intrinsics;
    EXPECT_DOUBLE_EQ(k.fx, 130.0 / (1 << l));
    EXPECT_DOUBLE_EQ(k.cx, 79.5 / (1 << l));
    for (int v = 0; v < level.height(); ++v) {
      for (int u = 0; u < level.width(); ++u) {
        const cv::Vec3f p = level.xyz.at<cv::Vec3f>(v, u);
        // Border pixels average an asymmetric window (X is linear in u),
        // which reaches two pixels in at every level; the rest project
        // exactly.
        if (u < 2 || v < 2 || u > level.width() - 3 || v > level.height() - 3) {
          continue;
        }
        EXPECT_NEAR(k.fx * p[0] / p[2] + k.cx, u, 1e-3) << "level " << l;
        EXPECT_NEAR(k.fy * p[1] / p[2] + k.cy, v, 1e-3) << "level " << l;
      }
    }
  }
}

TEST(CloudPyramidTest, HoleBesideAStepNeitherSpreadsNaNNorPullsDepths) {
  // z = 1 m in columns 0..15, a 4-column hole, z = 2 m in 20..39. No
  // 5-tap window spans both sides, so every level-1 depth must be exactly
  // 1 or 2: treating the hole as 0 would pull the edges towards 0,
  // propagating NaN would blank them.
  std::vector<float> z(40, 1.0f);
  for (int u = 16; u < 20; ++u) z[u] = kNaN;
  for (int u = 20; u < 40; ++u) z[u] = 2.0f;
  absl::StatusOr<OrganizedCloud> level1 = DownsampleCloud(ColumnsCloud(z, 12));
  ASSERT_TRUE(level1.ok()) << level1.status();
  ASSERT_EQ(level1->width(), 20);
  ASSERT_EQ(level1->height(), 6);
  for (int v = 0; v < level1->height(); ++v) {
    for (int u = 0; u < level1->width(); ++u) {
      ASSERT_TRUE(level1->HasPoint(u, v)) << u << "," << v;
      // Centre column 2u: 14..18 sees only z = 1, 16..20 only z = 2.
      const float expected = 2 * u <= 16 ? 1.0f : 2.0f;
      EXPECT_FLOAT_EQ(level1->xyz.at<cv::Vec3f>(v, u)[2], expected)
          << u << "," << v;
    }
  }
}

TEST(CloudPyramidTest, PixelWithoutValidNeighbourStaysNaNOthersKeepDepth) {
  // An 8-column hole (10..17): level-1 columns 6 and 7 (fine windows
  // 10..14 and 12..16) see no valid pixel; column 8 (14..18) sees one.
  std::vector<float> z(32, 1.25f);
  for (int u = 10; u < 18; ++u) z[u] = kNaN;
  absl::StatusOr<OrganizedCloud> level1 = DownsampleCloud(ColumnsCloud(z, 8));
  ASSERT_TRUE(level1.ok()) << level1.status();
  for (int v = 0; v < level1->height(); ++v) {
    for (int u = 0; u < level1->width(); ++u) {
      const cv::Vec3f p = level1->xyz.at<cv::Vec3f>(v, u);
      if (u == 6 || u == 7) {
        EXPECT_TRUE(std::isnan(p[0]) && std::isnan(p[1]) && std::isnan(p[2]));
      } else {
        EXPECT_FLOAT_EQ(p[2], 1.25f) << u << "," << v;
      }
    }
  }
}

TEST(CloudPyramidTest, SizesHalveRoundingUpAndStopAtTheMinimum) {
  std::vector<float> z(101, 1.0f);
  const OrganizedCloud cloud = ColumnsCloud(z, 37);
  absl::StatusOr<CloudPyramid> pyramid = BuildCloudPyramid(cloud, {});
  ASSERT_TRUE(pyramid.ok()) << pyramid.status();
  // 101x37, 51x19, 26x10, 13x5; 7x3 would be under min_size 4.
  const int widths[] = {101, 51, 26, 13};
  const int heights[] = {37, 19, 10, 5};
  ASSERT_EQ(pyramid->size(), 4);
  for (int l = 0; l < 4; ++l) {
    EXPECT_EQ(pyramid->levels[l].width(), widths[l]);
    EXPECT_EQ(pyramid->levels[l].height(), heights[l]);
    EXPECT_EQ(pyramid->levels[l].color.size(), pyramid->levels[l].xyz.size());
  }
  // Level 0 is the input itself (shared pixels).
  EXPECT_EQ(pyramid->levels[0].xyz.data, cloud.xyz.data);

  CloudPyramidOptions two;
  two.max_levels = 2;
  absl::StatusOr<CloudPyramid> short_pyramid = BuildCloudPyramid(cloud, two);
  ASSERT_TRUE(short_pyramid.ok());
  EXPECT_EQ(short_pyramid->size(), 2);

  CloudPyramidOptions large;
  large.min_size = 200;  // larger than the input: level 0 only
  absl::StatusOr<CloudPyramid> single = BuildCloudPyramid(cloud, large);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->size(), 1);
}

TEST(CloudPyramidTest, NormalsStayUnitLengthOnARenderedScene) {
  const synth::SynthScene scene = synth::GenerateScene(1);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  absl::StatusOr<CloudPyramid> pyramid = BuildCloudPyramid(*cloud, {});
  ASSERT_TRUE(pyramid.ok()) << pyramid.status();
  ASSERT_EQ(pyramid->size(), 8);  // 640x480, 320x240, ..., 10x8, 5x4
  for (int l = 0; l < pyramid->size(); ++l) {
    const cv::Mat& normals = pyramid->levels[l].normals;
    int valid = 0;
    for (int v = 0; v < normals.rows; ++v) {
      for (int u = 0; u < normals.cols; ++u) {
        const cv::Vec3f m = normals.at<cv::Vec3f>(v, u);
        if (std::isnan(m[2])) continue;
        ++valid;
        EXPECT_NEAR(cv::norm(m), 1.0, 1e-5) << "level " << l;
      }
    }
    EXPECT_GT(valid, 0) << "level " << l;
  }
}

TEST(CloudPyramidTest, RejectsBadOptionsAndMalformedClouds) {
  OrganizedCloud empty;
  EXPECT_EQ(BuildCloudPyramid(empty, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  const OrganizedCloud cloud = ColumnsCloud(std::vector<float>(8, 1.0f), 8);
  CloudPyramidOptions bad;
  bad.max_levels = 0;
  absl::Status status = BuildCloudPyramid(cloud, bad).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("max_levels"), std::string::npos);
  OrganizedCloud wrong = cloud;
  wrong.normals = cv::Mat(3, 3, CV_32FC3);
  EXPECT_EQ(DownsampleCloud(wrong).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
