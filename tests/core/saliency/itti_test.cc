#include "core/saliency/itti.h"

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

TEST(IttiSaliencyTest, RedDiscOnGreyIsTheMostSalientSpot) {
  const cv::Point center(184, 64);
  absl::StatusOr<cv::Mat> map =
      ComputeIttiSaliency(RedDiscOnGrey(center), IttiOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, cv::Size(256, 192));
  cv::Point peak;
  double hi = 0.0;
  cv::minMaxLoc(*map, nullptr, &hi, nullptr, &peak);
  EXPECT_FLOAT_EQ(hi, 1.0f);
  // Level 4 (the map level) has 16 px cells: the peak lies on the disc or
  // within one cell of its rim.
  EXPECT_LT(cv::norm(peak - center), 12.0 + 16.0) << peak;
  // Far from the disc (the opposite half of the image) nothing stands out.
  double far_max = 0.0;
  cv::minMaxLoc((*map)(cv::Rect(0, 0, 96, 192)), nullptr, &far_max);
  EXPECT_LT(far_max, 0.2);
}

TEST(IttiSaliencyTest, OddOrientationPopsOut) {
  // N(.) must suppress the 23 equal peaks of the horizontal bars and keep
  // the single one of the vertical bar.
  absl::StatusOr<cv::Mat> map = ComputeIttiSaliency(OddBarOut(), {});
  ASSERT_TRUE(map.ok()) << map.status();
  cv::Point peak;
  cv::minMaxLoc(*map, nullptr, nullptr, nullptr, &peak);
  EXPECT_LT(cv::norm(peak - cv::Point(kOddBarX, kOddBarY)), 30.0) << peak;
}

TEST(IttiSaliencyTest, ValidateNamesTheField) {
  const auto expect_rejected = [](IttiOptions options, const char* field) {
    const absl::Status s = Validate(options);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << field;
    EXPECT_NE(std::string(s.message()).find(field), std::string::npos)
        << s.message();
  };
  EXPECT_TRUE(Validate(IttiOptions{}).ok());
  IttiOptions o;
  o.min_center_level = 5;  // above max_center_level 4
  expect_rejected(o, "itti.min_center_level");
  o = {};
  o.min_delta = 0;
  expect_rejected(o, "itti.min_delta");
  o = {};
  o.max_delta = 9;
  expect_rejected(o, "itti.max_delta");
  o = {};
  o.map_level = -1;
  expect_rejected(o, "itti.map_level");
  o = {};
  o.gabor_wavelength_px = 0.0;
  expect_rejected(o, "itti.gabor_wavelength_px");
  o = {};
  o.gabor_sigma_px = -1.0;
  expect_rejected(o, "itti.gabor_sigma_px");
  o = {};
  o.gabor_kernel_size = 8;
  expect_rejected(o, "itti.gabor_kernel_size");
  o = {};
  o.color_intensity_threshold = 1.0f;
  expect_rejected(o, "itti.color_intensity_threshold");
  o = {};
  o.local_max_threshold = NAN;
  expect_rejected(o, "itti.local_max_threshold");
  o = {};
  o.color_weight = -1.0f;
  expect_rejected(o, "itti.color_weight");
  o = {};
  o.intensity_weight = o.color_weight = o.orientation_weight = 0.0f;
  expect_rejected(o, "itti.intensity_weight");
  // ComputeIttiSaliency checks the options too.
  o = {};
  o.gabor_kernel_size = 2;
  EXPECT_EQ(ComputeIttiSaliency(RedDiscOnGrey({64, 64}), o).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
