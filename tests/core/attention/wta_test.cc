#include "core/attention/wta.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "tests/core/attention/test_maps.h"

namespace fovea {
namespace {

using testing::AddBlob;

double Distance(const AttentionPoint& p, double u, double v) {
  return std::hypot(p.u - u, p.v - v);
}

// Three blobs of decreasing strength, 80 px or more apart.
cv::Mat ThreeBlobs() {
  cv::Mat map(160, 240, CV_32FC1, cv::Scalar(0));
  AddBlob(map, 40, 40, 8, 1.0f);
  AddBlob(map, 200, 120, 8, 0.7f);
  AddBlob(map, 200, 40, 8, 0.4f);
  return map;
}

TEST(WtaTest, WinnersComeStrongestBlobFirstEachBlobOnce) {
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(ThreeBlobs(), 10, {});
  ASSERT_TRUE(points.ok()) << points.status();
  // Inhibition of return: each blob wins once, then nothing is left above
  // the firing floor, so the network stops by itself before 10 points.
  ASSERT_EQ(points->size(), 3u);
  EXPECT_LE(Distance((*points)[0], 40, 40), 2.0);
  EXPECT_LE(Distance((*points)[1], 200, 120), 2.0);
  EXPECT_LE(Distance((*points)[2], 200, 40), 2.0);
  EXPECT_GT((*points)[0].saliency, (*points)[1].saliency);
  EXPECT_GT((*points)[1].saliency, (*points)[2].saliency);
}

TEST(WtaTest, InhibitionOfReturnMovesTheFocusOffAPlateau) {
  // A large uniform plateau: without inhibition of return its first cell
  // would win every selection. With a 20 px disc, successive winners are
  // distinct and at least about a disc radius apart.
  cv::Mat map(64, 128, CV_32FC1, cv::Scalar(0));
  map(cv::Rect(0, 0, 128, 64)).setTo(1.0f);
  WtaOptions options;
  options.ior_radius_px = 20.0f;
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(map, 6, options);
  ASSERT_TRUE(points.ok());
  ASSERT_EQ(points->size(), 6u);
  for (size_t i = 0; i < points->size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      EXPECT_GT(Distance((*points)[i], (*points)[j].u, (*points)[j].v), 16.0)
          << i << " vs " << j;
    }
  }
}

TEST(WtaTest, MaxPointsIsRespected) {
  const cv::Mat map = ThreeBlobs();
  EXPECT_EQ(ExtractWtaPoints(map, 2, {})->size(), 2u);
  EXPECT_EQ(ExtractWtaPoints(map, 1, {})->size(), 1u);
  EXPECT_TRUE(ExtractWtaPoints(map, 0, {})->empty());
}

TEST(WtaTest, EmptyMapGivesNoPoints) {
  cv::Mat zeros(48, 64, CV_32FC1, cv::Scalar(0));
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(zeros, 5, {});
  ASSERT_TRUE(points.ok());
  EXPECT_TRUE(points->empty());
  cv::Mat nans(48, 64, CV_32FC1,
               cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_TRUE(ExtractWtaPoints(nans, 5, {})->empty());
}

TEST(WtaTest, WeakCellsBelowTheFiringFloorNeverWin) {
  // With the defaults a cell needs about 5 % of the maximum to fire within
  // max_time_s; a 3 % blob never does, a 10 % blob does.
  cv::Mat map(64, 192, CV_32FC1, cv::Scalar(0));
  map(cv::Rect(0, 0, 16, 16)).setTo(1.0f);
  map(cv::Rect(80, 32, 16, 16)).setTo(0.1f);
  map(cv::Rect(160, 32, 16, 16)).setTo(0.03f);
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(map, 5, {});
  ASSERT_TRUE(points.ok());
  ASSERT_EQ(points->size(), 2u);
  EXPECT_LE(Distance((*points)[1], 87.5, 39.5), 1.0);
}

TEST(WtaTest, PointIsTheSaliencyWeightedCentreOfTheWinningCell) {
  cv::Mat map(32, 32, CV_32FC1, cv::Scalar(0));
  map.at<float>(3, 4) = 1.0f;
  map.at<float>(3, 8) = 1.0f;  // same cell at level 4: centre (6, 3)
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(map, 1, {});
  ASSERT_TRUE(points.ok());
  ASSERT_EQ(points->size(), 1u);
  EXPECT_EQ((*points)[0].u, 6);
  EXPECT_EQ((*points)[0].v, 3);
  EXPECT_FLOAT_EQ((*points)[0].saliency, 2.0f / 256.0f);
}

TEST(WtaTest, RejectsBadInputNamingTheField) {
  cv::Mat map(16, 16, CV_32FC1, cv::Scalar(1));
  const auto message = [&](const WtaOptions& options) {
    const absl::Status s = ExtractWtaPoints(map, 3, options).status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
    return std::string(s.message());
  };
  WtaOptions o;
  o.level = 9;
  EXPECT_NE(message(o).find("wta.level"), std::string::npos);
  o = {};
  o.time_step_s = 0.0f;
  EXPECT_NE(message(o).find("wta.time_step_s"), std::string::npos);
  o = {};
  o.capacitance_f = -1.0f;
  EXPECT_NE(message(o).find("wta.capacitance_f"), std::string::npos);
  o = {};
  o.leak_conductance_s = 1.0f;  // dt g / C = 1e5: Euler unstable
  EXPECT_NE(message(o).find("wta.leak_conductance_s"), std::string::npos);
  o = {};
  o.threshold_v = 0.0f;
  EXPECT_NE(message(o).find("wta.threshold_v"), std::string::npos);
  o = {};
  o.input_current_a = std::nanf("");
  EXPECT_NE(message(o).find("wta.input_current_a"), std::string::npos);
  o = {};
  o.max_time_s = 1e4f;  // 1e8 steps
  EXPECT_NE(message(o).find("wta.max_time_s"), std::string::npos);
  o = {};
  o.ior_radius_px = -1.0f;
  EXPECT_NE(message(o).find("wta.ior_radius_px"), std::string::npos);
  EXPECT_EQ(ExtractWtaPoints(cv::Mat(), 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ExtractWtaPoints(cv::Mat(8, 8, CV_8UC1), 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ExtractWtaPoints(map, -1, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  map.at<float>(3, 3) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(ExtractWtaPoints(map, 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// A 640x480 map like a table scene's: WTA finds most of its six regions
// (its time is fovea-bench's BM_Wta).
TEST(WtaTest, FindsTheRegionsOfA640x480Map) {
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractWtaPoints(testing::SceneLikeMap(), 10, {});
  ASSERT_TRUE(points.ok());
  EXPECT_GE(points->size(), 6u);
}

}  // namespace
}  // namespace fovea
