#include "core/saliency/hou.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tests/core/saliency/color_test_images.h"

namespace fovea {
namespace {

using testing::ExpectIsSaliencyMap;
using testing::RedDiscOnGrey;

TEST(HouSaliencyTest, RedDiscOnGreyIsTheMostSalientSpot) {
  const cv::Point center(184, 64);
  absl::StatusOr<cv::Mat> map =
      ComputeHouSaliency(RedDiscOnGrey(center), HouOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, cv::Size(256, 192));
  cv::Point peak;
  double hi = 0.0;
  cv::minMaxLoc(*map, nullptr, &hi, nullptr, &peak);
  EXPECT_FLOAT_EQ(hi, 1.0f);
  // The spectrum is taken at 64 px width (4 px cells): the peak lies on the
  // disc or within two cells of its rim.
  EXPECT_LT(cv::norm(peak - center), 12.0 + 8.0) << peak;
  // Far from the disc (the opposite half of the image) nothing stands out.
  double far_max = 0.0;
  cv::minMaxLoc((*map)(cv::Rect(0, 0, 96, 192)), nullptr, &far_max);
  EXPECT_LT(far_max, 0.2);
}

TEST(HouSaliencyTest, ValidateNamesTheField) {
  const auto expect_rejected = [](HouOptions options, const char* field) {
    const absl::Status s = Validate(options);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << field;
    EXPECT_NE(std::string(s.message()).find(field), std::string::npos)
        << s.message();
  };
  EXPECT_TRUE(Validate(HouOptions{}).ok());
  HouOptions o;
  o.working_width = 4;
  expect_rejected(o, "hou.working_width");
  o = {};
  o.average_size = 4;
  expect_rejected(o, "hou.average_size");
  o = {};
  o.blur_sigma_px = 0.0;
  expect_rejected(o, "hou.blur_sigma_px");
  o = {};
  o.average_size = 1;
  EXPECT_EQ(ComputeHouSaliency(RedDiscOnGrey({64, 64}), o).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
