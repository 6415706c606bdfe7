#include "core/pyramid/fusion.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace fovea {
namespace {

// A 3x5 map with value base + 0.1 * (column) in every row.
cv::Mat Ramp(float base, float step) {
  cv::Mat map(3, 5, CV_32FC1);
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) map.at<float>(v, u) = base + step * u;
  }
  return map;
}

TEST(FusionTest, SumRenormalisesTheWeightsToSumToOne) {
  const cv::Mat a = Ramp(0.0f, 0.25f), b = Ramp(1.0f, -0.25f);
  // Weights 3 and 1 act as 0.75 and 0.25.
  absl::StatusOr<cv::Mat> fused =
      FuseChannels({a, b}, {3.0f, 1.0f}, ChannelFusion::kSum);
  ASSERT_TRUE(fused.ok()) << fused.status();
  for (int u = 0; u < 5; ++u) {
    EXPECT_NEAR(fused->at<float>(1, u),
                0.75f * a.at<float>(1, u) + 0.25f * b.at<float>(1, u), 1e-6f);
  }
  // Scaling all weights changes nothing.
  absl::StatusOr<cv::Mat> scaled =
      FuseChannels({a, b}, {30.0f, 10.0f}, ChannelFusion::kSum);
  ASSERT_TRUE(scaled.ok());
  EXPECT_LT(cv::norm(*fused, *scaled, cv::NORM_INF), 1e-6);
}

TEST(FusionTest, MaxIsThePixelWiseMaximumWithEqualWeights) {
  const cv::Mat a = Ramp(0.0f, 0.25f), b = Ramp(1.0f, -0.25f);
  const cv::Mat c = Ramp(0.3f, 0.0f);
  absl::StatusOr<cv::Mat> fused =
      FuseChannels({a, b, c}, {0.5f, 0.5f, 0.5f}, ChannelFusion::kMax);
  ASSERT_TRUE(fused.ok()) << fused.status();
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 5; ++u) {
      const float expected =
          std::max({a.at<float>(v, u), b.at<float>(v, u), c.at<float>(v, u)});
      EXPECT_FLOAT_EQ(fused->at<float>(v, u), expected) << u << "," << v;
    }
  }
  // A channel of weight 0 is left out; a half weight halves the channel.
  fused = FuseChannels({a, b}, {1.0f, 0.0f}, ChannelFusion::kMax);
  ASSERT_TRUE(fused.ok());
  EXPECT_LT(cv::norm(*fused, a, cv::NORM_INF), 1e-7);
  fused = FuseChannels({a, b}, {1.0f, 0.5f}, ChannelFusion::kMax);
  ASSERT_TRUE(fused.ok());
  EXPECT_FLOAT_EQ(fused->at<float>(0, 0), 0.5f);  // max(0, 0.5 * 1)
  EXPECT_FLOAT_EQ(fused->at<float>(0, 4), 1.0f);  // max(1, 0.5 * 0)
}

TEST(FusionTest, RejectsMismatchedOrInvalidInputs) {
  const cv::Mat a = Ramp(0.0f, 0.1f);
  EXPECT_FALSE(FuseChannels({}, {}, ChannelFusion::kSum).ok());
  EXPECT_FALSE(FuseChannels({a, a}, {1.0f}, ChannelFusion::kSum).ok());
  EXPECT_FALSE(FuseChannels({a, a}, {0.0f, 0.0f}, ChannelFusion::kSum).ok());
  absl::Status status =
      FuseChannels({a, a}, {1.0f, -1.0f}, ChannelFusion::kMax).status();
  EXPECT_NE(status.message().find("weights[1]"), std::string::npos) << status;
  status = FuseChannels({a, cv::Mat::zeros(4, 5, CV_32FC1)}, {1.0f, 1.0f},
                        ChannelFusion::kSum)
               .status();
  EXPECT_NE(status.message().find("maps[1]"), std::string::npos) << status;
  EXPECT_FALSE(FuseChannels({a}, {std::numeric_limits<float>::infinity()},
                            ChannelFusion::kSum)
                   .ok());
}

}  // namespace
}  // namespace fovea
