#include "core/frame/hole_filling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// 100 x 60: a red surface at 1.0 m (columns < 50) beside a blue one at
// 1.5 m, with a 20 x 20 hole straddling the colour edge.
RgbdFrame TwoSurfacesWithAHole() {
  RgbdFrame frame;
  frame.intrinsics = {100, 100, 49.5, 29.5};
  frame.color = cv::Mat(60, 100, CV_8UC3, cv::Scalar(200, 30, 30));
  frame.color(cv::Rect(50, 0, 50, 60)).setTo(cv::Scalar(30, 30, 200));
  frame.depth = cv::Mat(60, 100, CV_32FC1, cv::Scalar(1.0f));
  frame.depth(cv::Rect(50, 0, 50, 60)).setTo(1.5f);
  frame.depth(cv::Rect(40, 20, 20, 20)).setTo(kNaN);
  return frame;
}

TEST(HoleFillingTest, DepthFollowsColourAndDoesNotCrossColourEdges) {
  const RgbdFrame frame = TwoSurfacesWithAHole();
  absl::StatusOr<FilledDepth> filled = FillDepthHoles(frame, {});
  ASSERT_TRUE(filled.ok()) << filled.status();
  EXPECT_EQ(filled->filled_pixels, 400);
  for (int v = 20; v < 40; ++v) {
    for (int u = 40; u < 60; ++u) {
      const float d = filled->depth.at<float>(v, u);
      ASSERT_FALSE(std::isnan(d)) << u << "," << v;
      EXPECT_NEAR(d, u < 50 ? 1.0f : 1.5f, 0.01f) << u << "," << v;
      EXPECT_EQ(filled->filled.at<uint8_t>(v, u), 255);
    }
  }
}

TEST(HoleFillingTest, OriginalDepthIsKeptAndNotMarked) {
  const RgbdFrame frame = TwoSurfacesWithAHole();
  absl::StatusOr<FilledDepth> filled = FillDepthHoles(frame, {});
  ASSERT_TRUE(filled.ok());
  EXPECT_EQ(filled->depth.at<float>(5, 5), 1.0f);
  EXPECT_EQ(filled->depth.at<float>(5, 95), 1.5f);
  EXPECT_EQ(filled->filled.at<uint8_t>(5, 5), 0);
  EXPECT_EQ(cv::countNonZero(filled->filled), filled->filled_pixels);
}

TEST(HoleFillingTest, HolesAboveTheSizeLimitStayEmpty) {
  const RgbdFrame frame = TwoSurfacesWithAHole();
  HoleFillingOptions options;
  options.max_hole_pixels = 399;
  absl::StatusOr<FilledDepth> filled = FillDepthHoles(frame, options);
  ASSERT_TRUE(filled.ok());
  EXPECT_EQ(filled->filled_pixels, 0);
  EXPECT_TRUE(std::isnan(filled->depth.at<float>(30, 50)));
}

TEST(HoleFillingTest, AHoleWithoutAPathOfSimilarColourStaysEmpty) {
  RgbdFrame frame = TwoSurfacesWithAHole();
  // A green patch inside the hole: no neighbour with depth has its colour.
  frame.color(cv::Rect(44, 24, 4, 4)).setTo(cv::Scalar(30, 220, 30));
  absl::StatusOr<FilledDepth> filled = FillDepthHoles(frame, {});
  ASSERT_TRUE(filled.ok());
  EXPECT_TRUE(std::isnan(filled->depth.at<float>(25, 45)));
  EXPECT_FALSE(std::isnan(filled->depth.at<float>(21, 41)));
}

TEST(HoleFillingTest, ValidateNamesTheField) {
  HoleFillingOptions options;
  options.color_sigma = 0.0f;
  EXPECT_NE(Validate(options).message().find("hole_filling.color_sigma"),
            std::string::npos);
}

}  // namespace
}  // namespace fovea
