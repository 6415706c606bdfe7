#include "core/pyramid/normalization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace fovea {
namespace {

// Adds a Gaussian bump of the given peak and sigma (pixels) at (u, v),
// taking the pixel-wise maximum with what is there.
void AddPeak(cv::Mat& map, int u, int v, float peak, float sigma = 1.5f) {
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) {
      const float r2 =
          static_cast<float>((x - u) * (x - u) + (y - v) * (y - v));
      const float value = peak * std::exp(-r2 / (2 * sigma * sigma));
      map.at<float>(y, x) = std::max(map.at<float>(y, x), value);
    }
  }
}

float Max(const cv::Mat& map) {
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  return static_cast<float>(max_value);
}

TEST(NormalizationTest, LinDividesByTheMaximum) {
  cv::Mat map = cv::Mat::zeros(20, 30, CV_32FC1);
  map.at<float>(5, 7) = 4.0f;
  map.at<float>(10, 20) = 1.0f;
  absl::StatusOr<cv::Mat> out = NormalizeMap(map, MapNormalization::kLin, {});
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_FLOAT_EQ(out->at<float>(5, 7), 1.0f);
  EXPECT_FLOAT_EQ(out->at<float>(10, 20), 0.25f);
  EXPECT_FLOAT_EQ(map.at<float>(5, 7), 4.0f);  // input untouched
}

TEST(NormalizationTest, AllZeroStaysZeroForEveryKind) {
  const cv::Mat zeros = cv::Mat::zeros(9, 13, CV_32FC1);
  for (MapNormalization kind : {MapNormalization::kLin, MapNormalization::kNms,
                                MapNormalization::kNlm}) {
    absl::StatusOr<cv::Mat> out = NormalizeMap(zeros, kind, {});
    ASSERT_TRUE(out.ok()) << out.status();
    ASSERT_EQ(out->size(), zeros.size());
    EXPECT_EQ(cv::countNonZero(*out), 0);
  }
  absl::StatusOr<cv::Mat> empty =
      NormalizeMap(cv::Mat(), MapNormalization::kNms, {});
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());
}

TEST(NormalizationTest, NmsBoostsOneStrongPeakOverSeveralEqualStrongPeaks) {
  // Map A: one peak 1.0 and twelve equal weak peaks 0.2. Eq. 2.38 gives
  // (1 - mean of the others)^2 = (1 - 0.2)^2 = 0.64.
  // Map B: four equal peaks 1.0: the other maxima average 1, so
  // (1 - 1)^2 = 0 and the map is suppressed.
  cv::Mat a = cv::Mat::zeros(60, 90, CV_32FC1);
  AddPeak(a, 45, 30, 1.0f);
  for (int i = 0; i < 12; ++i) AddPeak(a, 6 + 7 * i, 8 + 40 * (i % 2), 0.2f);
  cv::Mat b = cv::Mat::zeros(60, 90, CV_32FC1);
  for (int i = 0; i < 4; ++i) AddPeak(b, 10 + 20 * i, 30, 1.0f);

  absl::StatusOr<cv::Mat> na = NormalizeMap(a, MapNormalization::kNms, {});
  absl::StatusOr<cv::Mat> nb = NormalizeMap(b, MapNormalization::kNms, {});
  ASSERT_TRUE(na.ok() && nb.ok());
  EXPECT_NEAR(Max(*na), 0.64f, 1e-4f);
  EXPECT_NEAR(Max(*nb), 0.0f, 1e-6f);
  EXPECT_GT(Max(*na), Max(*nb));
  // The shape is kept: the weak peaks scale by the same factor.
  EXPECT_NEAR(na->at<float>(8, 6), 0.2f * 0.64f, 1e-4f);
}

TEST(NormalizationTest, NmsIgnoresPeaksBelowMinPeakAndCountsPlateausOnce) {
  // One peak 1.0, weak bumps at 0.05 (< min_peak 0.1, ignored) and a flat
  // plateau of 0.5 (one maximum, not 25): factor (1 - 0.5)^2.
  cv::Mat map = cv::Mat::zeros(40, 50, CV_32FC1);
  AddPeak(map, 10, 10, 1.0f);
  AddPeak(map, 40, 30, 0.05f);
  AddPeak(map, 40, 8, 0.05f);
  map(cv::Rect(20, 25, 5, 5)).setTo(0.5f);
  absl::StatusOr<cv::Mat> out = NormalizeMap(map, MapNormalization::kNms, {});
  ASSERT_TRUE(out.ok());
  EXPECT_NEAR(Max(*out), 0.25f, 1e-5f);
}

TEST(NormalizationTest, PlateauNextToAHigherPixelIsNoMaximum) {
  cv::Mat map = cv::Mat::zeros(10, 10, CV_32FC1);
  map(cv::Rect(2, 2, 5, 3)).setTo(0.5f);
  map.at<float>(2, 6) = 0.9f;  // on the plateau's corner
  const std::vector<LocalMaximum> maxima = FindLocalMaxima(map, 0.1f, 0.0f);
  ASSERT_EQ(maxima.size(), 1u);
  EXPECT_EQ(maxima[0].pixel, cv::Point(6, 2));
}

TEST(NormalizationTest, MinPeakDistanceDropsMaximaNearAHigherOne) {
  cv::Mat map = cv::Mat::zeros(20, 40, CV_32FC1);
  map.at<float>(10, 10) = 1.0f;
  map.at<float>(10, 14) = 0.8f;  // 4 px away
  map.at<float>(10, 30) = 0.6f;  // 20 px away
  EXPECT_EQ(FindLocalMaxima(map, 0.1f, 0.0f).size(), 3u);
  const std::vector<LocalMaximum> kept = FindLocalMaxima(map, 0.1f, 5.0f);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].pixel, cv::Point(10, 10));
  EXPECT_EQ(kept[1].pixel, cv::Point(30, 10));
}

TEST(NormalizationTest, NlmDividesBySqrtOfTheNearMaximalPeakCount) {
  // Four peaks within 10 % of the maximum (1.0, 0.95, 0.92, 0.91) and one
  // outside (0.5): divide by sqrt(4) = 2.
  cv::Mat map = cv::Mat::zeros(30, 100, CV_32FC1);
  const float peaks[] = {1.0f, 0.95f, 0.92f, 0.91f, 0.5f};
  for (int i = 0; i < 5; ++i) AddPeak(map, 10 + 20 * i, 15, 2.0f * peaks[i]);
  absl::StatusOr<cv::Mat> out = NormalizeMap(map, MapNormalization::kNlm, {});
  ASSERT_TRUE(out.ok());
  EXPECT_NEAR(out->at<float>(15, 10), 0.5f, 1e-5f);
  EXPECT_NEAR(out->at<float>(15, 90), 0.25f, 1e-5f);

  NormalizationOptions wide;
  wide.nlm_range = 0.6f;  // all five count
  out = NormalizeMap(map, MapNormalization::kNlm, wide);
  ASSERT_TRUE(out.ok());
  EXPECT_NEAR(out->at<float>(15, 10), 1.0f / std::sqrt(5.0f), 1e-5f);
}

TEST(NormalizationTest, NonSquareMapsWorkInBothOrientations) {
  // Peaks at the far corners of wide and tall maps: an index mix-up of
  // rows and columns would miss or misplace them.
  for (const cv::Size size : {cv::Size(97, 13), cv::Size(13, 97)}) {
    cv::Mat map = cv::Mat::zeros(size, CV_32FC1);
    map.at<float>(size.height - 1, size.width - 1) = 2.0f;
    map.at<float>(0, 0) = 1.0f;
    const std::vector<LocalMaximum> maxima = FindLocalMaxima(map, 0.1f, 0.0f);
    ASSERT_EQ(maxima.size(), 2u);
    EXPECT_EQ(maxima[0].pixel, cv::Point(size.width - 1, size.height - 1));
    EXPECT_EQ(maxima[1].pixel, cv::Point(0, 0));
    absl::StatusOr<cv::Mat> nms = NormalizeMap(map, MapNormalization::kNms, {});
    ASSERT_TRUE(nms.ok());
    ASSERT_EQ(nms->size(), size);
    // Scaled: 1 and 0.5; factor (1 - 0.5)^2 = 0.25.
    EXPECT_NEAR(nms->at<float>(size.height - 1, size.width - 1), 0.25f, 1e-6f);
    EXPECT_NEAR(nms->at<float>(0, 0), 0.125f, 1e-6f);
    absl::StatusOr<cv::Mat> nlm = NormalizeMap(map, MapNormalization::kNlm, {});
    ASSERT_TRUE(nlm.ok());
    EXPECT_NEAR(nlm->at<float>(size.height - 1, size.width - 1), 1.0f, 1e-6f);
  }
}

TEST(NormalizationTest, RejectsBadMapsAndOptions) {
  cv::Mat map = cv::Mat::zeros(4, 4, CV_32FC1);
  map.at<float>(1, 2) = -1.0f;
  absl::Status status = NormalizeMap(map, MapNormalization::kLin, {}).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("(2, 1)"), std::string::npos) << status;
  map.at<float>(1, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(NormalizeMap(map, MapNormalization::kLin, {}).ok());
  EXPECT_FALSE(
      NormalizeMap(cv::Mat::zeros(4, 4, CV_8UC1), MapNormalization::kLin, {})
          .ok());
  NormalizationOptions bad;
  bad.nlm_range = 1.5f;
  status =
      NormalizeMap(cv::Mat::zeros(4, 4, CV_32FC1), MapNormalization::kNlm, bad)
          .status();
  EXPECT_NE(status.message().find("nlm_range"), std::string::npos) << status;
}

}  // namespace
}  // namespace fovea
