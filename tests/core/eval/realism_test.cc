#include "core/eval/realism.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace fovea {
namespace {

using ::testing::DoubleNear;

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

TEST(KolmogorovSmirnovTest, EqualSamplesAreZeroDisjointOnesOne) {
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({1, 2, 3}, {3, 2, 1}), 0.0);
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({1, 2, 3}, {4, 5}), 1.0);
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({4, 5}, {1, 2, 3}), 1.0);
}

TEST(KolmogorovSmirnovTest, HalfShiftedSampleIsHalf) {
  // {1, 2, 3, 4} against {3, 4, 5, 6}: at 2, F_a = 0.5 and F_b = 0.
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({1, 2, 3, 4}, {3, 4, 5, 6}), 0.5);
}

TEST(KolmogorovSmirnovTest, TiesOpenNoGapAndNaNsAreIgnored) {
  // Both are "all zeros": a gap measured between the copies of a tied value
  // would report 1.
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({0, 0, 0}, {0, 0}), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_DOUBLE_EQ(KolmogorovSmirnov({1, nan, 2}, {1, 2}), 0.0);
  EXPECT_TRUE(std::isnan(KolmogorovSmirnov({}, {1})));
  EXPECT_TRUE(std::isnan(KolmogorovSmirnov({nan}, {1})));
}

// A 64 x 64 frame looking straight down at a table 1 m away (z = 1 for
// every point, normal (0, 0, -1) towards the camera), with Gaussian depth
// noise of `sigma` m, the pixels of `holes` without depth.
struct TestScene {
  OrganizedCloud cloud;
  SupportPlane plane;
  TableScene table;
};

TestScene FlatTable(float sigma, const cv::Rect& hole, float rim_step) {
  TestScene s;
  const int n = 64;
  s.cloud.intrinsics = {64.0, 64.0, 31.5, 31.5};
  s.cloud.xyz.create(n, n, CV_32FC3);
  s.cloud.normals.create(n, n, CV_32FC3);
  s.cloud.color.create(n, n, CV_8UC3);
  s.cloud.color.setTo(cv::Scalar(200, 200, 200));
  s.plane.normal = {0, 0, -1};
  s.plane.d = 1.0f;
  s.plane.inliers.create(n, n, CV_8UC1);
  s.plane.inliers.setTo(cv::Scalar(255));
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, sigma);
  for (int v = 0; v < n; ++v) {
    for (int u = 0; u < n; ++u) {
      float z = 1.0f + (sigma > 0 ? noise(rng) : 0.0f);
      // Right of the hole the surface is rim_step nearer: the hole lies at
      // a depth edge when rim_step is large.
      if (u >= hole.x + hole.width) z -= rim_step;
      const float x = (u - 31.5f) / 64.0f * z, y = (v - 31.5f) / 64.0f * z;
      s.cloud.xyz.at<cv::Vec3f>(v, u) = {x, y, z};
      s.cloud.normals.at<cv::Vec3f>(v, u) = {0, 0, -1};
      if (hole.contains({u, v})) {
        s.cloud.xyz.at<cv::Vec3f>(v, u) = {kNaNf, kNaNf, kNaNf};
        s.cloud.normals.at<cv::Vec3f>(v, u) = {kNaNf, kNaNf, kNaNf};
        s.plane.inliers.at<uint8_t>(v, u) = 0;
        s.cloud.color.at<cv::Vec3b>(v, u) = {10, 10, 10};  // dark
      }
    }
  }
  s.plane.inlier_count = cv::countNonZero(s.plane.inliers);
  s.table.region = s.plane.inliers.clone();
  s.table.standing = cv::Mat::zeros(n, n, CV_8UC1);
  s.table.height = cv::Mat::zeros(n, n, CV_32FC1);
  return s;
}

TEST(CollectRealismSamplesTest, PlaneNoiseOverZSquaredIsTheSensorsSigma) {
  const TestScene s = FlatTable(0.002f, cv::Rect(), 0.0f);
  RealismOptions options;
  options.cell_px = 80;  // 8 px at 64 columns
  const RealismSamples r =
      CollectRealismSamples(s.cloud, s.plane, s.table, cv::Mat(), options);
  ASSERT_EQ(r.plane_noise.size(), 64u);  // 8 x 8 cells
  double mean = 0;
  for (double x : r.plane_noise) mean += x;
  mean /= r.plane_noise.size();
  // At z = 1 the residual sigma is the noise's (a little below it: the
  // cell's own plane absorbs 3 of 64 degrees of freedom).
  EXPECT_THAT(mean, DoubleNear(0.002, 0.0003));
  EXPECT_THAT(r.plane_noise_depth[0], DoubleNear(1.0, 0.01));
  EXPECT_DOUBLE_EQ(r.missing_fraction, 0.0);
  EXPECT_TRUE(std::isnan(r.missing_at_edges));  // no hole at all
  EXPECT_DOUBLE_EQ(r.table_share, 1.0);
}

TEST(CollectRealismSamplesTest, AHoleAtADepthEdgeCountsAsAnEdgeHole) {
  const cv::Rect hole(20, 10, 4, 40);  // 160 pixels
  RealismOptions options;
  options.hull_erode_px = 0;
  const TestScene edge = FlatTable(0.0f, hole, 0.10f);
  const RealismSamples at_edge = CollectRealismSamples(
      edge.cloud, edge.plane, edge.table, cv::Mat(), options);
  EXPECT_THAT(at_edge.missing_fraction, DoubleNear(160.0 / (64 * 64), 1e-9));
  EXPECT_DOUBLE_EQ(at_edge.missing_at_edges, 1.0);
  // Every dark pixel is a missing one.
  EXPECT_DOUBLE_EQ(at_edge.missing_on_dark, 1.0);
  const TestScene flat = FlatTable(0.0f, hole, 0.0f);
  const RealismSamples on_plane = CollectRealismSamples(
      flat.cloud, flat.plane, flat.table, cv::Mat(), options);
  EXPECT_DOUBLE_EQ(on_plane.missing_at_edges, 0.0);
}

TEST(CollectRealismSamplesTest, ObjectsOutsideTheTableSceneAreCounted) {
  TestScene s = FlatTable(0.0f, cv::Rect(), 0.0f);
  cv::Mat labels(64, 64, CV_32SC1, cv::Scalar(1));
  labels(cv::Rect(0, 0, 10, 10)).setTo(cv::Scalar(20));    // object 2
  labels(cv::Rect(40, 40, 10, 10)).setTo(cv::Scalar(30));  // object 3
  // Object 3 is outside the table scene, object 2 in it and standing.
  s.table.region(cv::Rect(40, 40, 10, 10)).setTo(cv::Scalar(0));
  s.table.standing(cv::Rect(0, 0, 10, 10)).setTo(cv::Scalar(255));
  s.table.height(cv::Rect(0, 0, 10, 10)).setTo(cv::Scalar(0.05));
  const RealismSamples r =
      CollectRealismSamples(s.cloud, s.plane, s.table, labels, {});
  EXPECT_THAT(r.object_in_scene, ::testing::ElementsAre(1.0, 0.0));
  EXPECT_THAT(r.object_standing, ::testing::ElementsAre(1.0, 0.0));
  EXPECT_THAT(r.object_bottom[0], DoubleNear(0.05, 1e-6));
}

TEST(CompareRealismTest, NamesEveryStatisticAndFindsTheOneThatDiffers) {
  RealismSet real, synthetic;
  RealismSamples a, b;
  a.plane_noise = {1e-3, 1.2e-3, 1.4e-3};
  b.plane_noise = {5e-3, 6e-3};  // five times noisier: KS 1
  a.normal_angle = b.normal_angle = {1, 2, 3};
  AddToSet(a, real);
  AddToSet(b, synthetic);
  real.same_relations = {{0.1, 0.9}, {0.2, 0.8}};
  synthetic.same_relations = {{0.1, 0.1}, {0.2, 0.2}};
  const std::vector<RealismDistance> rows =
      CompareRealism(real, synthetic, {"colour", "convexity"});
  ASSERT_EQ(rows.size(), RealismStatisticNames().size() + 1 + 4);
  EXPECT_EQ(rows[0].statistic, "plane_noise");
  EXPECT_DOUBLE_EQ(rows[0].ks, 1.0);
  EXPECT_THAT(rows[0].real_median, DoubleNear(1.2e-3, 1e-12));
  const RealismSummary same = SummarizeRealism(rows, "same.");
  EXPECT_EQ(same.rows, 2);
  EXPECT_EQ(same.worst, "same.convexity");
  EXPECT_DOUBLE_EQ(same.max_ks, 1.0);
  EXPECT_DOUBLE_EQ(same.mean_ks, 0.5);
  // No different-object pairs on either side: no number, not a zero.
  EXPECT_EQ(SummarizeRealism(rows, "different.").rows, 0);
}

}  // namespace
}  // namespace fovea
