#include "core/attention/msr.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/core/attention/test_maps.h"

namespace fovea {
namespace {

using testing::AddBlob;

TEST(MsrTest, FirstPointLiesOnTheMostSalientBlobNearItsCentre) {
  cv::Mat map(60, 80, CV_32FC1, cv::Scalar(0));
  AddBlob(map, 20, 30, 5, 0.6f);
  AddBlob(map, 60, 20, 6, 1.0f);
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractMsrPoints(map, 5, {});
  ASSERT_TRUE(points.ok());
  ASSERT_GE(points->size(), 2u);
  EXPECT_NEAR((*points)[0].u, 60, 1);
  EXPECT_NEAR((*points)[0].v, 20, 1);
  EXPECT_FLOAT_EQ((*points)[0].saliency, 1.0f);
  EXPECT_NEAR((*points)[1].u, 20, 1);
  EXPECT_NEAR((*points)[1].v, 30, 1);
}

TEST(MsrTest, RegionIsInhibitedSoAPlateauYieldsOnePoint) {
  cv::Mat map(40, 40, CV_32FC1, cv::Scalar(0));
  map(cv::Rect(5, 5, 20, 10)).setTo(0.9f);
  map(cv::Rect(10, 8, 3, 3)).setTo(1.0f);  // within 25 % of the plateau
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractMsrPoints(map, 10, {});
  ASSERT_TRUE(points.ok());
  ASSERT_EQ(points->size(), 1u);
  // Centred on the plateau, not at its brightest corner.
  EXPECT_NEAR((*points)[0].u, 14.5, 1.5);
  EXPECT_NEAR((*points)[0].v, 9.5, 1.5);
}

TEST(MsrTest, PointLiesOnTheRegionEvenWhenItIsNotConvex) {
  cv::Mat map(50, 50, CV_32FC1, cv::Scalar(0));
  // An L: its centroid is off the shape.
  map(cv::Rect(5, 5, 5, 40)).setTo(1.0f);
  map(cv::Rect(5, 40, 40, 5)).setTo(1.0f);
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractMsrPoints(map, 1, {});
  ASSERT_TRUE(points.ok());
  ASSERT_EQ(points->size(), 1u);
  EXPECT_EQ(map.at<float>((*points)[0].v, (*points)[0].u), 1.0f);
}

TEST(MsrTest, StopsAtMaxPointsAndOnAnEmptyMap) {
  cv::Mat map(60, 80, CV_32FC1, cv::Scalar(0));
  for (int i = 0; i < 4; ++i) AddBlob(map, 10 + 18 * i, 30, 3, 1.0f - 0.1f * i);
  EXPECT_EQ(ExtractMsrPoints(map, 2, {})->size(), 2u);
  EXPECT_EQ(ExtractMsrPoints(map, 10, {})->size(), 4u);
  cv::Mat empty(10, 10, CV_32FC1, cv::Scalar(0));
  EXPECT_TRUE(ExtractMsrPoints(empty, 5, {})->empty());
}

TEST(MsrTest, RejectsBadInputNamingTheField) {
  MsrOptions options;
  options.region_tolerance = 1.5f;
  cv::Mat map(10, 10, CV_32FC1, cv::Scalar(0));
  const absl::Status s = ExtractMsrPoints(map, 3, options).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("msr.region_tolerance"), std::string::npos);
  EXPECT_EQ(ExtractMsrPoints(cv::Mat(), 3, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea

namespace fovea {
namespace {

TEST(MsrTest, WithoutSlopeInhibitionTheRimOfABlobSeedsAgain) {
  cv::Mat map(60, 80, CV_32FC1, cv::Scalar(0));
  AddBlob(map, 40, 30, 6, 1.0f);
  MsrOptions thesis;
  thesis.inhibit_slope = false;
  EXPECT_GT(ExtractMsrPoints(map, 5, thesis)->size(), 1u);
  EXPECT_EQ(ExtractMsrPoints(map, 5, {})->size(), 1u);
}

}  // namespace
}  // namespace fovea
