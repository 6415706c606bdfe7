#include "core/saliency/harel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tests/core/saliency/color_test_images.h"

namespace fovea {
namespace {

using testing::ExpectIsSaliencyMap;
using testing::kOddBarX;
using testing::kOddBarY;
using testing::OddBarOut;
using testing::RedDiscOnGrey;

TEST(HarelSaliencyTest, RedDiscOnGreyIsTheMostSalientSpot) {
  const cv::Point center(184, 64);
  absl::StatusOr<cv::Mat> map =
      ComputeHarelSaliency(RedDiscOnGrey(center), HarelOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, cv::Size(256, 192));
  cv::Point peak;
  double hi = 0.0;
  cv::minMaxLoc(*map, nullptr, &hi, nullptr, &peak);
  EXPECT_FLOAT_EQ(hi, 1.0f);
  // The grid is 32 x 24 (8 px cells) and the map is blurred: the peak lies
  // on the disc or within two cells of its rim.
  EXPECT_LT(cv::norm(peak - center), 12.0 + 16.0) << peak;
  // Far from the disc (the opposite half of the image) nothing stands out.
  double far_max = 0.0;
  cv::minMaxLoc((*map)(cv::Rect(0, 0, 96, 192)), nullptr, &far_max);
  EXPECT_LT(far_max, 0.2);
}

TEST(HarelSaliencyTest, OrientationChannelFindsTheOddBar) {
  // The orientation channel alone: the vertical bar is the only strong
  // response in the vertical-orientation maps. (With all channels the
  // centre bias of the activation chain lets central horizontal bars win in
  // the intensity channel; see the header.)
  HarelOptions options;
  options.intensity_weight = 0.0f;
  options.color_weight = 0.0f;
  absl::StatusOr<cv::Mat> map = ComputeHarelSaliency(OddBarOut(), options);
  ASSERT_TRUE(map.ok()) << map.status();
  cv::Point peak;
  cv::minMaxLoc(*map, nullptr, nullptr, nullptr, &peak);
  EXPECT_LT(cv::norm(peak - cv::Point(kOddBarX, kOddBarY)), 30.0) << peak;
}

TEST(HarelSaliencyTest, WarmStartGivesTheEquilibriumOfPowerIteration) {
  // The detailed-balance start is exact for both chains: iterating from the
  // uniform distribution to a tight tolerance reaches the same map.
  const cv::Mat image = RedDiscOnGrey({184, 64});
  HarelOptions cold;
  cold.warm_start = false;
  cold.tolerance = 1e-7f;
  cold.max_iterations = 5000;
  absl::StatusOr<cv::Mat> warm_map = ComputeHarelSaliency(image, {});
  absl::StatusOr<cv::Mat> cold_map = ComputeHarelSaliency(image, cold);
  ASSERT_TRUE(warm_map.ok()) << warm_map.status();
  ASSERT_TRUE(cold_map.ok()) << cold_map.status();
  EXPECT_LT(cv::norm(*warm_map, *cold_map, cv::NORM_INF), 1e-3);
}

TEST(HarelSaliencyTest, ValidateNamesTheField) {
  const auto expect_rejected = [](HarelOptions options, const char* field) {
    const absl::Status s = Validate(options);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << field;
    EXPECT_NE(std::string(s.message()).find(field), std::string::npos)
        << s.message();
  };
  EXPECT_TRUE(Validate(HarelOptions{}).ok());
  HarelOptions o;
  o.grid_long_side = 1;
  expect_rejected(o, "harel.grid_long_side");
  o = {};
  o.grid_long_side = kHarelMaxGridSide + 1;
  expect_rejected(o, "harel.grid_long_side");
  o = {};
  o.min_feature_level = 5;
  expect_rejected(o, "harel.min_feature_level");
  o = {};
  o.activation_sigma_fraction = 0.0f;
  expect_rejected(o, "harel.activation_sigma_fraction");
  o = {};
  o.normalization_sigma_fraction = -1.0f;
  expect_rejected(o, "harel.normalization_sigma_fraction");
  o = {};
  o.log_floor = 0.0f;
  expect_rejected(o, "harel.log_floor");
  o = {};
  o.max_iterations = 0;
  expect_rejected(o, "harel.max_iterations");
  o = {};
  o.tolerance = NAN;
  expect_rejected(o, "harel.tolerance");
  o = {};
  o.blur_fraction = -0.1f;
  expect_rejected(o, "harel.blur_fraction");
  o = {};
  o.gabor_kernel_size = 4;
  expect_rejected(o, "harel.gabor_kernel_size");
  o = {};
  o.orientation_weight = -1.0f;
  expect_rejected(o, "harel.orientation_weight");
  o = {};
  o.intensity_weight = o.color_weight = o.orientation_weight = 0.0f;
  expect_rejected(o, "harel.intensity_weight");
  o = {};
  o.max_iterations = -3;
  EXPECT_EQ(ComputeHarelSaliency(RedDiscOnGrey({64, 64}), o).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
