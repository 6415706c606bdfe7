#include "core/attention/tj.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "tests/core/attention/test_maps.h"

namespace fovea {
namespace {

cv::Mat Zeros(int width, int height) {
  return cv::Mat(height, width, CV_32FC1, cv::Scalar(0));
}

std::vector<AttentionPoint> Extract(const cv::Mat& map, int max_points = 10,
                                    const TjOptions& options = {}) {
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractTjPoints(map, max_points, options);
  EXPECT_TRUE(points.ok()) << points.status();
  return points.ok() ? *points : std::vector<AttentionPoint>{};
}

double Distance(const AttentionPoint& p, double u, double v) {
  return std::hypot(p.u - u, p.v - v);
}

// Number of connected components of the pixels where `mask` is `value`,
// with 8-connectivity or 4-connectivity. The image is padded by one pixel
// of value 0, so for value 0 the outside is one component.
int CountComponents(const cv::Mat& mask, bool value, bool eight) {
  cv::Mat padded;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::Mat seen(padded.size(), CV_8UC1, cv::Scalar(0));
  int count = 0;
  std::vector<cv::Point> stack;
  for (int v = 0; v < padded.rows; ++v) {
    for (int u = 0; u < padded.cols; ++u) {
      if ((padded.at<uint8_t>(v, u) != 0) != value || seen.at<uint8_t>(v, u)) {
        continue;
      }
      ++count;
      stack.assign(1, {u, v});
      seen.at<uint8_t>(v, u) = 1;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        for (int dv = -1; dv <= 1; ++dv) {
          for (int du = -1; du <= 1; ++du) {
            if ((du == 0 && dv == 0) || (!eight && du != 0 && dv != 0)) {
              continue;
            }
            const cv::Point q(p.x + du, p.y + dv);
            if (q.x < 0 || q.y < 0 || q.x >= padded.cols ||
                q.y >= padded.rows || seen.at<uint8_t>(q) ||
                (padded.at<uint8_t>(q) != 0) != value) {
              continue;
            }
            seen.at<uint8_t>(q) = 1;
            stack.push_back(q);
          }
        }
      }
    }
  }
  return count;
}

bool Has2x2Block(const cv::Mat& skeleton) {
  for (int v = 0; v + 1 < skeleton.rows; ++v) {
    for (int u = 0; u + 1 < skeleton.cols; ++u) {
      if (skeleton.at<uint8_t>(v, u) && skeleton.at<uint8_t>(v, u + 1) &&
          skeleton.at<uint8_t>(v + 1, u) &&
          skeleton.at<uint8_t>(v + 1, u + 1)) {
        return true;
      }
    }
  }
  return false;
}

// Skeleton is inside the mask, one pixel wide, and has the mask's
// components (8-connected) and holes (4-connected background).
void ExpectTopologyPreservingThinning(const cv::Mat& mask) {
  absl::StatusOr<cv::Mat> skeleton = ThinToSkeleton(mask);
  ASSERT_TRUE(skeleton.ok());
  EXPECT_EQ(cv::countNonZero(*skeleton & ~mask), 0);
  EXPECT_FALSE(Has2x2Block(*skeleton));
  EXPECT_EQ(CountComponents(*skeleton, true, true),
            CountComponents(mask, true, true));
  EXPECT_EQ(CountComponents(*skeleton, false, false),
            CountComponents(mask, false, false));
}

TEST(TjTest, OnePixelWidePlusYieldsItsCrossing) {
  cv::Mat map = Zeros(41, 41);
  map(cv::Rect(5, 20, 31, 1)).setTo(1.0f);
  map(cv::Rect(20, 5, 1, 31)).setTo(1.0f);
  const std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].u, 20);
  EXPECT_EQ(points[0].v, 20);
  EXPECT_FLOAT_EQ(points[0].saliency, 1.0f);
}

TEST(TjTest, ThickPlusYieldsAJunctionAtItsCentre) {
  cv::Mat map = Zeros(41, 41);
  map(cv::Rect(4, 18, 33, 5)).setTo(1.0f);
  map(cv::Rect(18, 4, 5, 33)).setTo(1.0f);
  const std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(Distance(points[0], 20, 20), 1.5);
}

TEST(TjTest, ThickTYieldsItsJunction) {
  cv::Mat map = Zeros(60, 50);
  map(cv::Rect(5, 10, 41, 5)).setTo(1.0f);   // bar, centre line v = 12
  map(cv::Rect(23, 10, 5, 32)).setTo(1.0f);  // stem, centre line u = 25
  const std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(Distance(points[0], 25, 12), 2.0);
  absl::StatusOr<cv::Mat> skeleton = ThinToSkeleton(map > 0);
  ASSERT_TRUE(skeleton.ok());
  EXPECT_GE(SkeletonBranchCount(*skeleton, points[0].u, points[0].v), 3);
}

TEST(TjTest, OfSeveralJunctionsTheMostSalientWins) {
  // An H: junctions at (10, 20) and (30, 20); the right half is brighter.
  cv::Mat map = Zeros(41, 41);
  map(cv::Rect(10, 5, 1, 31)).setTo(0.8f);
  map(cv::Rect(30, 5, 1, 31)).setTo(1.0f);
  map(cv::Rect(11, 20, 9, 1)).setTo(0.8f);
  map(cv::Rect(20, 20, 10, 1)).setTo(1.0f);
  TjOptions most_salient;
  most_salient.junction = TjJunction::kMostSalient;
  const std::vector<AttentionPoint> points = Extract(map, 10, most_salient);
  ASSERT_EQ(points.size(), 1u);
  // Guo-Hall moves the junction of a one-pixel T by a pixel into the stem.
  EXPECT_LE(Distance(points[0], 30, 20), 1.0);
}

TEST(TjTest, OfSeveralJunctionsTheCentralOneWinsByDefault) {
  // A comb: a bar along row 20 crossed by three teeth at columns 10, 30
  // and 50, so three crossings; the component's centroid is (30, 20). The
  // right tooth is the brightest, so kMostSalient takes its crossing.
  cv::Mat map = Zeros(61, 41);
  map(cv::Rect(5, 20, 51, 1)).setTo(0.6f);
  map(cv::Rect(10, 5, 1, 31)).setTo(0.6f);
  map(cv::Rect(30, 5, 1, 31)).setTo(0.6f);
  map(cv::Rect(50, 5, 1, 31)).setTo(1.0f);
  std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(Distance(points[0], 30, 20), 1.0);
  TjOptions most_salient;
  most_salient.junction = TjJunction::kMostSalient;
  points = Extract(map, 10, most_salient);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(Distance(points[0], 50, 20), 1.0);
}

TEST(TjTest, StraightBarYieldsItsMiddle) {
  cv::Mat map = Zeros(60, 40);
  map(cv::Rect(10, 20, 41, 5)).setTo(1.0f);  // centre (30, 22)
  std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(Distance(points[0], 30, 22), 1.0);
  // A one-pixel-wide diagonal line: the middle pixel exactly.
  map = Zeros(40, 40);
  for (int i = 5; i <= 25; ++i) map.at<float>(i, i + 3) = 0.5f;
  points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].u, 18);
  EXPECT_EQ(points[0].v, 15);
}

TEST(TjTest, RingYieldsAPointOnTheRing) {
  cv::Mat map = Zeros(61, 61);
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) {
      const double r = std::hypot(u - 30, v - 30);
      if (r >= 12.0 && r <= 15.0) map.at<float>(v, u) = 1.0f;
    }
  }
  const std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_GT(map.at<float>(points[0].v, points[0].u), 0.0f);
  EXPECT_GE(Distance(points[0], 30, 30), 12.0);
  EXPECT_LE(Distance(points[0], 30, 30), 15.0);
  // A one-pixel loop (square outline) too.
  cv::Mat square = Zeros(20, 20);
  cv::rectangle(square, cv::Rect(4, 4, 10, 10), cv::Scalar(1.0), 1);
  const std::vector<AttentionPoint> on_square = Extract(square);
  ASSERT_EQ(on_square.size(), 1u);
  EXPECT_EQ(square.at<float>(on_square[0].v, on_square[0].u), 1.0f);
}

TEST(TjTest, SinglePixelYieldsItself) {
  cv::Mat map = Zeros(20, 15);
  map.at<float>(9, 7) = 0.7f;
  const std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].u, 7);
  EXPECT_EQ(points[0].v, 9);
  EXPECT_FLOAT_EQ(points[0].saliency, 0.7f);
  // Two pixels and a 2x2 square are skeletons of their own too.
  map = Zeros(20, 15);
  map(cv::Rect(2, 2, 2, 1)).setTo(1.0f);
  map(cv::Rect(10, 10, 2, 2)).setTo(1.0f);
  EXPECT_EQ(Extract(map).size(), 2u);
}

TEST(TjTest, ComponentsWithMeanBelowThetaSalAreDropped) {
  cv::Mat map = Zeros(80, 30);
  map(cv::Rect(2, 2, 10, 10)).setTo(1.0f);
  // Mean about 0.054 < 0.1: dropped although its peak is 0.5.
  map(cv::Rect(20, 2, 10, 10)).setTo(0.05f);
  map.at<float>(6, 25) = 0.5f;
  map(cv::Rect(40, 2, 10, 10)).setTo(0.12f);  // kept
  std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_LT(points[0].u, 12);
  EXPECT_GE(points[1].u, 40);
  TjOptions keep_all;
  keep_all.min_mean_fraction = 0.0f;
  EXPECT_EQ(Extract(map, 10, keep_all).size(), 3u);
}

TEST(TjTest, PointsAreRankedByComponentMeanSaliency) {
  cv::Mat map = Zeros(90, 20);
  map(cv::Rect(2, 2, 20, 5)).setTo(0.3f);
  map(cv::Rect(32, 2, 20, 5)).setTo(0.9f);
  map(cv::Rect(62, 2, 20, 5)).setTo(0.6f);
  // A small very bright spot does not lift a component's mean over 0.9.
  map.at<float>(4, 10) = 1.0f;
  std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_TRUE(points[0].u >= 32 && points[0].u < 52);
  EXPECT_TRUE(points[1].u >= 62);
  EXPECT_TRUE(points[2].u < 22);
  EXPECT_GT(points[0].saliency, points[1].saliency);
  EXPECT_GT(points[1].saliency, points[2].saliency);
  points = Extract(map, 2);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_TRUE(points[1].u >= 62);
  EXPECT_TRUE(Extract(map, 0).empty());
}

TEST(TjTest, ByDefaultALargeComponentComesBeforeASmallBrightOne) {
  // A 30 x 30 object at 0.6 (total 540) and a 5 x 5 sliver at 1.0 (total
  // 25), as an occluder leaves of the object behind it.
  cv::Mat map = Zeros(80, 40);
  map(cv::Rect(2, 2, 30, 30)).setTo(0.6f);
  map(cv::Rect(60, 2, 5, 5)).setTo(1.0f);
  std::vector<AttentionPoint> points = Extract(map);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_LT(points[0].u, 32);
  EXPECT_GE(points[1].u, 60);
  // Total over the largest area: the big one's mean, then 25 / 900.
  EXPECT_NEAR(points[0].saliency, 0.6f, 1e-5);
  EXPECT_NEAR(points[1].saliency, 25.0f / 900.0f, 1e-5);
  TjOptions by_mean;
  by_mean.ranking = TjRanking::kMeanSaliency;
  points = Extract(map, 10, by_mean);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_GE(points[0].u, 60);
  EXPECT_FLOAT_EQ(points[0].saliency, 1.0f);
  EXPECT_NEAR(points[1].saliency, 0.6f, 1e-5);
}

TEST(TjTest, EmptyMapGivesNoPoints) {
  EXPECT_TRUE(Extract(Zeros(64, 48)).empty());
  cv::Mat nans(48, 64, CV_32FC1,
               cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_TRUE(Extract(nans).empty());
  cv::Mat negative(48, 64, CV_32FC1, cv::Scalar(-1));
  EXPECT_TRUE(Extract(negative).empty());
}

TEST(TjTest, ThinningAFilledRectangleGivesAOnePixelWideConnectedSkeleton) {
  cv::Mat mask(40, 50, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(5, 5, 36, 22)).setTo(255);
  absl::StatusOr<cv::Mat> skeleton = ThinToSkeleton(mask);
  ASSERT_TRUE(skeleton.ok());
  EXPECT_FALSE(Has2x2Block(*skeleton));
  EXPECT_EQ(CountComponents(*skeleton, true, true), 1);
  EXPECT_EQ(cv::countNonZero(*skeleton & ~mask), 0);
  // Not a dot: the medial axis of a 36 x 22 rectangle has a 14 px spine
  // plus four diagonal branches.
  EXPECT_GE(cv::countNonZero(*skeleton), 14);
  ExpectTopologyPreservingThinning(mask);
}

TEST(TjTest, ThinningPreservesComponentsAndHolesOfRandomShapes) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coordinate(0, 63), size(1, 14),
      count(1, 8);
  for (int trial = 0; trial < 200; ++trial) {
    cv::Mat mask(64, 64, CV_8UC1, cv::Scalar(0));
    const int shapes = count(rng);
    for (int i = 0; i < shapes; ++i) {
      const cv::Point c(coordinate(rng), coordinate(rng));
      const int s = size(rng);
      switch (trial % 3) {
        case 0:
          cv::circle(mask, c, s, cv::Scalar(255), -1);
          break;
        case 1:
          cv::rectangle(mask, cv::Rect(c.x, c.y, s, size(rng)), cv::Scalar(255),
                        -1);
          break;
        default:
          cv::circle(mask, c, s, cv::Scalar(255), 1 + s / 4);  // rings
      }
    }
    SCOPED_TRACE(trial);
    ExpectTopologyPreservingThinning(mask);
    // Every component yields one point, and it lies on the component.
    cv::Mat map;
    mask.convertTo(map, CV_32FC1, 1.0 / 255.0);
    const std::vector<AttentionPoint> points = Extract(map, 100);
    EXPECT_EQ(static_cast<int>(points.size()),
              CountComponents(mask, true, true));
    for (const AttentionPoint& p : points) {
      EXPECT_EQ(mask.at<uint8_t>(p.v, p.u), 255);
    }
  }
}

TEST(TjTest, BranchCountTellsEndsLinesStaircasesAndJunctions) {
  const auto skeleton = [](std::initializer_list<cv::Point> pixels) {
    cv::Mat s(7, 7, CV_8UC1, cv::Scalar(0));
    for (const cv::Point& p : pixels) s.at<uint8_t>(p) = 255;
    return s;
  };
  // End of a horizontal line.
  EXPECT_EQ(SkeletonBranchCount(skeleton({{3, 3}, {4, 3}, {5, 3}}), 3, 3), 1);
  // Middle of a line.
  EXPECT_EQ(SkeletonBranchCount(skeleton({{2, 3}, {3, 3}, {4, 3}}), 3, 3), 2);
  // 4-connected staircase: 3 or 4 neighbours, still a line.
  const cv::Mat stairs = skeleton({{1, 1}, {2, 1}, {2, 2}, {3, 2}, {3, 3}});
  EXPECT_EQ(SkeletonBranchCount(stairs, 2, 1), 2);
  EXPECT_EQ(SkeletonBranchCount(stairs, 2, 2), 2);
  // T and plus.
  EXPECT_EQ(
      SkeletonBranchCount(skeleton({{2, 3}, {3, 3}, {4, 3}, {3, 4}}), 3, 3), 3);
  EXPECT_EQ(SkeletonBranchCount(
                skeleton({{2, 3}, {3, 3}, {4, 3}, {3, 4}, {3, 2}}), 3, 3),
            4);
  // Y of diagonals.
  EXPECT_EQ(
      SkeletonBranchCount(skeleton({{2, 2}, {4, 2}, {3, 3}, {3, 4}}), 3, 3), 3);
  // Isolated pixel, and a pixel outside the image.
  EXPECT_EQ(SkeletonBranchCount(skeleton({{3, 3}}), 3, 3), 0);
  EXPECT_EQ(SkeletonBranchCount(skeleton({{0, 0}}), -1, 0), 0);
}

TEST(TjTest, RejectsBadInputNamingTheField) {
  TjOptions options;
  options.min_mean_fraction = 1.5f;
  cv::Mat map = Zeros(10, 10);
  const absl::Status s = ExtractTjPoints(map, 3, options).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("tj.min_mean_fraction"), std::string::npos);
  EXPECT_EQ(ExtractTjPoints(cv::Mat(), 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ExtractTjPoints(cv::Mat(8, 8, CV_8UC1), 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ExtractTjPoints(map, -1, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  map.at<float>(2, 2) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(ExtractTjPoints(map, 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ThinToSkeleton(cv::Mat()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// A 20 x 20 block (400 px) and a 5 x 5 speck (25 px), equally salient: with
// a 100 px floor only the block yields a point; with none, both do.
TEST(TjTest, ComponentsSmallerThanTheFloorGiveNoPoint) {
  cv::Mat map = Zeros(60, 60);
  map(cv::Rect(5, 5, 20, 20)).setTo(0.8f);
  map(cv::Rect(45, 45, 5, 5)).setTo(0.8f);
  TjOptions options;
  options.min_component_pixels = 100;
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractTjPoints(map, 10, options);
  ASSERT_TRUE(points.ok()) << points.status();
  ASSERT_EQ(points->size(), 1u);
  EXPECT_LT((*points)[0].u, 25);
  EXPECT_EQ(ExtractTjPoints(map, 10, {})->size(), 2u);
  options.min_component_pixels = -1;
  EXPECT_NE(ExtractTjPoints(map, 10, options)
                .status()
                .message()
                .find("tj.min_component_pixels"),
            std::string::npos);
}

// A 640x480 map like a table scene's (blobs cut at 5 % of their peak, as a
// normalised saliency map is zero away from objects, plus a thin bar):
// seven components, seven points (its time is fovea-bench's BM_Tj).
TEST(TjTest, OnePointPerComponentOfA640x480Map) {
  cv::Mat map = testing::SceneLikeMap(/*blob_cut=*/0.05f);
  map(cv::Rect(300, 40, 150, 12)).setTo(0.45f);
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractTjPoints(map, 10, {});
  ASSERT_TRUE(points.ok());
  EXPECT_EQ(points->size(), 7u);
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

// Two bright plateaus joined by a dim bridge: above zero they are one
// component (one point); above 30 % of the maximum they are two.
TEST(TjSupportTest, ASupportThresholdSeparatesObjectsJoinedByADimBridge) {
  cv::Mat map(40, 80, CV_32FC1, cv::Scalar(0));
  map(cv::Rect(5, 10, 20, 20)).setTo(1.0f);
  map(cv::Rect(55, 10, 20, 20)).setTo(0.9f);
  map(cv::Rect(25, 18, 30, 4)).setTo(0.05f);
  absl::StatusOr<std::vector<AttentionPoint>> joined =
      ExtractTjPoints(map, 5, TjOptions{});
  ASSERT_TRUE(joined.ok());
  EXPECT_EQ(joined->size(), 1u);
  TjOptions options;
  options.support_fraction = 0.3f;
  absl::StatusOr<std::vector<AttentionPoint>> apart =
      ExtractTjPoints(map, 5, options);
  ASSERT_TRUE(apart.ok());
  ASSERT_EQ(apart->size(), 2u);
  EXPECT_LT((*apart)[0].u, 25);  // the brighter plateau first
  EXPECT_GT((*apart)[1].u, 55);
  options.support_fraction = 1.0f;
  EXPECT_NE(Validate(options).message().find("tj.support_fraction"),
            std::string::npos);
}

}  // namespace
}  // namespace fovea
