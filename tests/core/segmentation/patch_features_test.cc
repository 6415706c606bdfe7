#include "core/segmentation/patch_features.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fovea {
namespace {

// Points of the surface z = 1 + slope * |x|, x in [-0.1, 0.1] m every 5 mm,
// y in [-0.1, 0.1] m every cm. Seen from the origin (the camera, looking
// along +z), slope > 0 is a ridge (its middle nearest) and slope < 0 a
// valley (its middle farthest).
std::vector<Eigen::Vector3f> Fold(float slope) {
  std::vector<Eigen::Vector3f> points;
  for (int i = -20; i <= 20; ++i) {
    for (int j = -10; j <= 10; ++j) {
      const float x = 0.005f * i;
      points.emplace_back(x, 0.01f * j, 1.0f + slope * std::abs(x));
    }
  }
  return points;
}

TEST(CameraFacingHullDistanceTest, ARidgeLiesOnTheFacesFacingTheCamera) {
  // The ridge's two flanks are the hull's camera-facing faces.
  EXPECT_LT(CameraFacingHullDistance(Fold(0.5f)), 1e-4f);
}

TEST(CameraFacingHullDistanceTest, AValleyLiesItsDepthBelowTheRimFace) {
  // The one camera-facing face spans the rims (z = 0.95); a point at |x|
  // lies 0.5 * (0.1 - |x|) behind it, 0.5 * (0.1 - mean |x|) on average,
  // and the grid's mean |x| is 2 * (1 + ... + 20) * 5 mm / 41 = 51.2 mm.
  const double expected = 0.5 * (0.1 - 2.0 * 210.0 * 0.005 / 41.0);
  EXPECT_NEAR(CameraFacingHullDistance(Fold(-0.5f)), expected, 5e-4);
}

TEST(CameraFacingHullDistanceTest, APlaneOrTooFewPointsGiveZero) {
  EXPECT_EQ(CameraFacingHullDistance(Fold(0.0f)), 0.0f);
  EXPECT_EQ(
      CameraFacingHullDistance({{0, 0, 1}, {0.1f, 0, 1}, {0, 0.1f, 1.1f}}),
      0.0f);
  EXPECT_EQ(CameraFacingHullDistance({}), 0.0f);
}

TEST(CameraFacingHullDistancesTest, OnePerPointAndTheValleyFloorIsDeepest) {
  const std::vector<Eigen::Vector3f> valley = Fold(-0.5f);
  const std::vector<float> d = CameraFacingHullDistances(valley);
  ASSERT_EQ(d.size(), valley.size());
  // Point (i = 0, j = 0) is on the floor: 5 cm deep; the rims are on the
  // face.
  EXPECT_NEAR(d[20 * 21 + 10], 0.05f, 5e-4f);
  EXPECT_NEAR(d[0], 0.0f, 5e-4f);
}

TEST(HistogramCorrelationTest, IsPearsonsCorrelation) {
  EXPECT_NEAR(HistogramCorrelation({1, 2, 3, 4}, {2, 4, 6, 8}), 1.0f, 1e-6f);
  EXPECT_NEAR(HistogramCorrelation({1, 2, 3, 4}, {4, 3, 2, 1}), -1.0f, 1e-6f);
  EXPECT_NEAR(HistogramCorrelation({1, 0, 1, 0}, {0, 1, 0, 1}), -1.0f, 1e-6f);
  EXPECT_EQ(HistogramCorrelation({0, 0, 0}, {1, 2, 3}), 0.0f);
  EXPECT_EQ(HistogramCorrelation({}, {}), 0.0f);
}

TEST(LabelColorHistogramsTest, ColouredPixelsByHueAndGreyOnesByValue) {
  // Label 0: saturated red; label 1: mid grey; label 2 absent; -1 ignored.
  cv::Mat rgb(2, 4, CV_8UC3, cv::Scalar(200, 10, 10));
  rgb.row(1).setTo(cv::Scalar(128, 128, 128));
  cv::Mat labels(2, 4, CV_32SC1, cv::Scalar(0));
  labels.row(1).setTo(1);
  labels.at<int>(0, 3) = -1;
  const PatchColorOptions options;
  const std::vector<std::vector<float>> h =
      LabelColorHistograms(rgb, labels, 3, options);
  ASSERT_EQ(h.size(), 3u);
  const int bins = HistogramBins(options);
  ASSERT_EQ(static_cast<int>(h[0].size()), bins);
  // Red: hue bin 0, top saturation bin.
  EXPECT_EQ(h[0][options.saturation_bins - 1], 3.0f);
  // Grey (value 128): grey bin 128 * gray_bins / 256.
  const int colored = options.hue_bins * options.saturation_bins;
  EXPECT_EQ(h[1][colored + 128 * options.gray_bins / 256], 4.0f);
  float empty = 0.0f;
  for (const float c : h[2]) empty += c;
  EXPECT_EQ(empty, 0.0f);
}

TEST(SampleLabelPointsTest, EvenlyUpToTheLimitAndAllOfSmallLabels) {
  OrganizedCloud cloud;
  cloud.xyz = cv::Mat(10, 10, CV_32FC3);
  cv::Mat labels(10, 10, CV_32SC1);
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 10; ++u) {
      cloud.xyz.at<cv::Vec3f>(v, u) = {0.01f * u, 0.01f * v, 1.0f};
      labels.at<int>(v, u) = v < 9 ? 0 : 1;  // 90 pixels and 10
    }
  }
  cloud.xyz.at<cv::Vec3f>(9, 9)[2] = std::nanf("");  // no depth
  const auto samples = SampleLabelPoints(cloud, labels, 2, 30);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].size(), 30u);
  EXPECT_EQ(samples[1].size(), 9u);  // all valid points of the small label
  // Evenly: every third pixel of label 0, so rows 0 to 8 are all visited.
  EXPECT_NEAR(samples[0].front().y(), 0.0f, 1e-6f);
  EXPECT_NEAR(samples[0].back().y(), 0.08f, 1e-6f);
}

TEST(PatchColorOptionsTest, ValidateNamesTheField) {
  PatchColorOptions options;
  options.hue_bins = 0;
  EXPECT_NE(Validate(options).message().find("hue_bins"), std::string::npos);
  options = {};
  options.min_saturation = 300;
  EXPECT_NE(Validate(options).message().find("min_saturation"),
            std::string::npos);
  EXPECT_TRUE(Validate(PatchColorOptions{}).ok());
}

}  // namespace
}  // namespace fovea
