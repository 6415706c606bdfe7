// What every whole-image colour operator promises, checked once for each:
// a uniform image gives an all-zero map, any size (odd, tiny) gives a map
// of that size in [0, 1], and a bad image is INVALID_ARGUMENT naming
// `color`. (KOOTSTRA has its own versions: it is not stretched to a peak
// of 1 on noise.)
#include <gtest/gtest.h>

#include <functional>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/saliency/harel.h"
#include "core/saliency/hou.h"
#include "core/saliency/itti.h"
#include "tests/core/saliency/color_test_images.h"

namespace fovea {
namespace {

using testing::ExpectIsSaliencyMap;
using testing::kGrey;
using testing::kRed;

struct ColorOperator {
  std::string name;
  std::function<absl::StatusOr<cv::Mat>(const cv::Mat&)> compute;
};

class ColorOperatorContractTest
    : public ::testing::TestWithParam<ColorOperator> {};

TEST_P(ColorOperatorContractTest, UniformImageGivesAnAllZeroMap) {
  const cv::Mat image(96, 128, CV_8UC3, cv::Scalar(40, 160, 90));
  absl::StatusOr<cv::Mat> map = GetParam().compute(image);
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  EXPECT_EQ(cv::countNonZero(*map), 0);
}

TEST_P(ColorOperatorContractTest,
       OddSizedNoiseGivesAMapInUnitRangeAtInputSize) {
  cv::Mat image(77, 101, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(256));
  absl::StatusOr<cv::Mat> map = GetParam().compute(image);
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  double hi = 0.0;
  cv::minMaxLoc(*map, nullptr, &hi);
  EXPECT_FLOAT_EQ(hi, 1.0f);
}

TEST_P(ColorOperatorContractTest, TinyImageStillGivesAMap) {
  cv::Mat image(3, 2, CV_8UC3, cv::Scalar(kGrey));
  image.at<cv::Vec3b>(1, 1) = kRed;
  absl::StatusOr<cv::Mat> map = GetParam().compute(image);
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
}

TEST_P(ColorOperatorContractTest,
       EmptyOrWrongTypeColorIsInvalidArgumentNamingColor) {
  absl::Status s = GetParam().compute(cv::Mat()).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "color: empty");
  s = GetParam().compute(cv::Mat(4, 4, CV_8UC1, cv::Scalar(0))).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("color:"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(
    ColorOperators, ColorOperatorContractTest,
    ::testing::Values(ColorOperator{"itti",
                                    [](const cv::Mat& c) {
                                      return ComputeIttiSaliency(c,
                                                                 IttiOptions{});
                                    }},
                      ColorOperator{"harel",
                                    [](const cv::Mat& c) {
                                      return ComputeHarelSaliency(
                                          c, HarelOptions{});
                                    }},
                      ColorOperator{"hou",
                                    [](const cv::Mat& c) {
                                      return ComputeHouSaliency(c,
                                                                HouOptions{});
                                    }}),
    [](const ::testing::TestParamInfo<ColorOperator>& info) {
      return info.param.name;
    });

}  // namespace
}  // namespace fovea
