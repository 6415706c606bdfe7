#include "core/saliency/top_down.h"

#include <gtest/gtest.h>

namespace fovea {
namespace {

TEST(TargetColorTest, TheYellowObjectIsTheMostSimilar) {
  cv::Mat color(40, 60, CV_8UC3, cv::Scalar(90, 90, 200));        // blue-ish
  color(cv::Rect(10, 10, 8, 8)).setTo(cv::Scalar(240, 220, 20));  // yellow
  color(cv::Rect(40, 20, 8, 8)).setTo(cv::Scalar(220, 30, 30));   // red
  TargetColorOptions options;
  options.rgb = {250, 230, 0};
  absl::StatusOr<cv::Mat> map = ComputeTargetColorSaliency(color, options);
  ASSERT_TRUE(map.ok());
  cv::Point max_at;
  cv::minMaxLoc(*map, nullptr, nullptr, nullptr, &max_at);
  EXPECT_TRUE(cv::Rect(10, 10, 8, 8).contains(max_at));
  EXPECT_LT(map->at<float>(24, 44), 0.1f);  // red
  EXPECT_LT(map->at<float>(35, 5), 0.1f);   // background
}

TEST(LocationPriorTest, PeaksAtItsCentreAndFallsOffAsAGaussian) {
  LocationPriorOptions options;
  options.u = 30;
  options.v = 10;
  options.sigma_px = 5;
  absl::StatusOr<cv::Mat> map = ComputeLocationPrior(60, 40, options);
  ASSERT_TRUE(map.ok());
  EXPECT_FLOAT_EQ(map->at<float>(10, 30), 1.0f);
  EXPECT_NEAR(map->at<float>(10, 35), std::exp(-0.5f), 1e-6f);
  EXPECT_NEAR(map->at<float>(15, 35), std::exp(-1.0f), 1e-6f);
}

TEST(TopDownTest, BadInputIsNamed) {
  TargetColorOptions color;
  color.sigma_delta_e = 0;
  EXPECT_NE(Validate(color).message().find("target_color.sigma_delta_e"),
            std::string::npos);
  LocationPriorOptions prior;
  prior.sigma_px = -1;
  EXPECT_NE(Validate(prior).message().find("location_prior.sigma_px"),
            std::string::npos);
  EXPECT_FALSE(ComputeTargetColorSaliency(cv::Mat(), {}).ok());
}

}  // namespace
}  // namespace fovea
