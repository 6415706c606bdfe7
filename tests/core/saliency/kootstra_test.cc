#include "core/saliency/kootstra.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tests/core/saliency/color_test_images.h"

namespace fovea {
namespace {

using testing::ExpectIsSaliencyMap;

const cv::Scalar kGrey(128, 128, 128);
const cv::Scalar kDark(30, 60, 90);

cv::Point Peak(const cv::Mat& map) {
  cv::Point peak;
  cv::minMaxLoc(map, nullptr, nullptr, nullptr, &peak);
  return peak;
}

// A dark filled disc: every rim pixel has a partner mirrored through the
// centre, so the pairs across the disc all vote at its centre.
TEST(KootstraSaliencyTest, FilledDiscIsMostSymmetricAtItsCentre) {
  cv::Mat image(192, 256, CV_8UC3, kGrey);
  const cv::Point center(170, 80);
  cv::circle(image, center, 20, kDark, cv::FILLED);
  absl::StatusOr<cv::Mat> map = ComputeKootstraSaliency(image, {});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  EXPECT_LT(cv::norm(Peak(*map) - center), 4.0) << Peak(*map);
}

TEST(KootstraSaliencyTest, FilledSquareIsMostSymmetricAtItsCentre) {
  cv::Mat image(192, 256, CV_8UC3, kGrey);
  cv::rectangle(image, cv::Rect(60, 100, 40, 40), kDark, cv::FILLED);
  absl::StatusOr<cv::Mat> map = ComputeKootstraSaliency(image, {});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  EXPECT_LT(cv::norm(Peak(*map) - cv::Point(80, 120)), 4.0) << Peak(*map);
}

// Random noise has strong gradients in all directions, which pair up with a
// mean phase weight of 1 instead of the 4 of mirrored gradients: a noise
// patch the size of the disc scores lower than the disc.
TEST(KootstraSaliencyTest, NoiseTextureScoresLowerThanADisc) {
  cv::Mat image(192, 256, CV_8UC3, kGrey);
  cv::Mat noise(48, 48, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat noise_rgb;
  cv::cvtColor(noise, noise_rgb, cv::COLOR_GRAY2RGB);
  const cv::Rect noise_box(40, 72, 48, 48);
  noise_rgb.copyTo(image(noise_box));
  const cv::Point center(190, 96);
  cv::circle(image, center, 20, kDark, cv::FILLED);
  absl::StatusOr<cv::Mat> map = ComputeKootstraSaliency(image, {});
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_LT(cv::norm(Peak(*map) - center), 4.0) << Peak(*map);
  double noise_max = 0.0;
  cv::minMaxLoc((*map)(noise_box), nullptr, &noise_max);
  EXPECT_LT(noise_max, 0.6);
}

TEST(KootstraSaliencyTest, UniformImageGivesAnAllZeroMap) {
  const cv::Mat image(96, 128, CV_8UC3, cv::Scalar(40, 160, 90));
  absl::StatusOr<cv::Mat> map = ComputeKootstraSaliency(image, {});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  EXPECT_EQ(cv::countNonZero(*map), 0);
}

TEST(KootstraSaliencyTest, OddSizedAndTinyImagesGiveMapsAtInputSize) {
  cv::Mat image(77, 101, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(256));
  absl::StatusOr<cv::Mat> map = ComputeKootstraSaliency(image, {});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, image.size());
  const cv::Mat tiny(2, 3, CV_8UC3, kGrey);
  map = ComputeKootstraSaliency(tiny, {});
  ASSERT_TRUE(map.ok()) << map.status();
  ExpectIsSaliencyMap(*map, tiny.size());
}

TEST(KootstraSaliencyTest, EmptyOrWrongTypeColorIsInvalidArgumentNamingColor) {
  absl::Status s = ComputeKootstraSaliency(cv::Mat(), {}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "color: empty");
  s = ComputeKootstraSaliency(cv::Mat(4, 4, CV_32FC3, cv::Scalar(0)), {})
          .status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("color:"), std::string::npos);
}

TEST(KootstraSaliencyTest, ValidateNamesTheField) {
  const auto expect_rejected = [](KootstraOptions options, const char* field) {
    const absl::Status s = Validate(options);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << field;
    EXPECT_NE(std::string(s.message()).find(field), std::string::npos)
        << s.message();
  };
  EXPECT_TRUE(Validate(KootstraOptions{}).ok());
  KootstraOptions o;
  o.min_level = -1;
  expect_rejected(o, "kootstra.min_level");
  o = {};
  o.num_scales = 0;
  expect_rejected(o, "kootstra.num_scales");
  o = {};
  o.num_scales = kKootstraMaxLevel + 1;
  expect_rejected(o, "kootstra.num_scales");
  o = {};
  o.radius_px = 0;
  expect_rejected(o, "kootstra.radius_px");
  o = {};
  o.distance_sigma_px = 0.0f;
  expect_rejected(o, "kootstra.distance_sigma_px");
  o = {};
  o.min_gradient = NAN;
  expect_rejected(o, "kootstra.min_gradient");
  o = {};
  o.max_points_per_scale = 1;
  expect_rejected(o, "kootstra.max_points_per_scale");
  o = {};
  o.smoothing_sigma_px = -1.0f;
  expect_rejected(o, "kootstra.smoothing_sigma_px");
  o = {};
  o.radius_px = 1000;
  EXPECT_EQ(
      ComputeKootstraSaliency(cv::Mat(8, 8, CV_8UC3, kGrey), o).status().code(),
      absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
