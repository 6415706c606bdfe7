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

// A sensor that drops every other column (or row, or every 4th column):
// each gap lies between two points of the plane and is bridged with the
// plane's own points, so normals come out everywhere as without gaps.
TEST(OrganizedCloudTest, RegularDropoutsOnASurfaceAreBridged) {
  const Eigen::Vector3f n = Eigen::Vector3f(0.0f, -1.0f, -1.0f).normalized();
  const RgbdFrame whole = testing::PlaneFrame(n, 0.9f);
  const OrganizedCloud truth = BackProject(whole);
  struct Pattern {
    const char* name;
    int column_period;  // 0: no missing columns
    int row_period;
  };
  for (const Pattern& pattern :
       {Pattern{"every other column", 2, 0}, Pattern{"every other row", 0, 2},
        Pattern{"every 4th column", 4, 0}}) {
    RgbdFrame frame = whole;
    frame.depth = whole.depth.clone();
    for (int v = 0; v < frame.height(); ++v) {
      for (int u = 0; u < frame.width(); ++u) {
        if ((pattern.column_period && u % pattern.column_period == 1) ||
            (pattern.row_period && v % pattern.row_period == 1)) {
          frame.depth.at<float>(v, u) = std::numeric_limits<float>::quiet_NaN();
        }
      }
    }
    absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
    ASSERT_TRUE(cloud.ok());
    for (int v = 15; v < 105; ++v) {
      for (int u = 15; u < 145; ++u) {
        ASSERT_TRUE(cloud->HasPoint(u, v))
            << pattern.name << " " << u << "," << v;
        const cv::Vec3f d =
            cloud->xyz.at<cv::Vec3f>(v, u) - truth.xyz.at<cv::Vec3f>(v, u);
        EXPECT_LT(cv::norm(d), 1e-4) << pattern.name << " " << u << "," << v;
        ASSERT_TRUE(cloud->HasNormal(u, v))
            << pattern.name << " " << u << "," << v;
      }
    }
  }
}

// With every 4th column missing, a gap at a depth step (where a sensor's
// own dropouts are) is not bridged, nor is a gap of four pixels; the
// regular gaps on either surface are.
TEST(OrganizedCloudTest, GapsAcrossADepthStepOrWideGapsStayEmpty) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.0f);
  frame.depth(cv::Rect(80, 0, 80, 120)).setTo(0.9f);
  for (int u = 1; u < frame.width(); u += 4) frame.depth.col(u).setTo(kNaN);
  frame.depth.col(79).setTo(kNaN);                   // 78 | 79 | 80
  frame.depth(cv::Rect(34, 0, 3, 120)).setTo(kNaN);  // 33-36
  const OrganizedCloud cloud = BackProject(frame);
  for (int v = 0; v < 120; v += 7) {
    EXPECT_FALSE(cloud.HasPoint(79, v)) << v;
    for (int u = 33; u <= 36; ++u) EXPECT_FALSE(cloud.HasPoint(u, v)) << u;
    for (int u : {5, 29, 77, 85, 157}) {
      ASSERT_TRUE(cloud.HasPoint(u, v)) << u << "," << v;
      EXPECT_NEAR(cloud.xyz.at<cv::Vec3f>(v, u)[2], u < 80 ? 1.0f : 0.9f,
                  1e-5f);
    }
  }
}

// An ordinary frame's few thin gaps (here one pixel in 50) are left as
// the sensor sent them.
TEST(OrganizedCloudTest, AFewThinGapsStayEmpty) {
  RgbdFrame frame = testing::PlaneFrame({0.0f, 0.0f, -1.0f}, 1.0f);
  for (int v = 0; v < frame.height(); ++v) {
    for (int u = (v * 7) % 50; u < frame.width(); u += 50) {
      frame.depth.at<float>(v, u) = std::numeric_limits<float>::quiet_NaN();
    }
  }
  const OrganizedCloud cloud = BackProject(frame);
  int points = 0;
  for (int v = 0; v < frame.height(); ++v) {
    for (int u = 0; u < frame.width(); ++u) {
      points += cloud.HasPoint(u, v);
      EXPECT_EQ(cloud.HasPoint(u, v), !std::isnan(frame.depth.at<float>(v, u)));
    }
  }
  EXPECT_LT(points, frame.width() * frame.height());
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
