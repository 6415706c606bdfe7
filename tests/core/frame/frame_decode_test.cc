// DecodeFrame on valid frames: raw rgb8 / bgr8 colour and 16UC1 / 32FC1
// depth (scaled to metres, invalid as NaN, row padding honoured), PNG and
// JPEG files decoded as the raw path decodes them, and the OSD PNG pair.
// Refusals are in frame_decode_refusal_test.cc.

#include "core/frame/frame_decode.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/frame/raw_frame_builders.h"

namespace fovea {
namespace {

using ::fovea::testing::Bytes;
using ::fovea::testing::CompressedFrom;
using ::fovea::testing::Encode;
using ::fovea::testing::FrameBytes;
using ::fovea::testing::kHeight;
using ::fovea::testing::kWidth;
using ::fovea::testing::RawFrom;
using ::fovea::testing::TestDepth16;
using ::fovea::testing::TestRgb;
using ::fovea::testing::ValidFrame;
using ::testing::HasSubstr;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Depth values equal, NaN matching NaN.
void ExpectSameDepth(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.type(), CV_32FC1);
  ASSERT_EQ(b.type(), CV_32FC1);
  for (int v = 0; v < a.rows; ++v) {
    for (int u = 0; u < a.cols; ++u) {
      const float x = a.at<float>(v, u);
      const float y = b.at<float>(v, u);
      if (std::isnan(x) || std::isnan(y)) {
        ASSERT_TRUE(std::isnan(x) && std::isnan(y)) << u << "," << v;
      } else {
        ASSERT_EQ(x, y) << u << "," << v;
      }
    }
  }
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         cv::norm(a, b, cv::NORM_INF) == 0.0;
}

template <typename F>
double MedianMilliseconds(int runs, F&& run) {
  std::vector<double> times;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    run();
    times.push_back(std::chrono::duration<double, std::milli>(
                        std::chrono::steady_clock::now() - start)
                        .count());
  }
  std::nth_element(times.begin(), times.begin() + runs / 2, times.end());
  return times[runs / 2];
}

// ---------------------------------------------------------------- decoded

TEST(FrameDecodeTest, Rgb8AndBgr8GiveTheSameRgb) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const absl::StatusOr<RgbdFrame> from_rgb = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(from_rgb.ok()) << from_rgb.status();

  cv::Mat bgr = TestRgb(kWidth, kHeight);
  for (int v = 0; v < bgr.rows; ++v) {
    for (int u = 0; u < bgr.cols; ++u) {
      std::swap(bgr.at<cv::Vec3b>(v, u)[0], bgr.at<cv::Vec3b>(v, u)[2]);
    }
  }
  const std::string bgr_bytes = Bytes(bgr);
  raw.color = RawFrom(bgr_bytes, bgr, "bgr8");
  const absl::StatusOr<RgbdFrame> from_bgr = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(from_bgr.ok()) << from_bgr.status();

  EXPECT_TRUE(SameImage(from_rgb->color, TestRgb(kWidth, kHeight)));
  EXPECT_TRUE(SameImage(from_bgr->color, from_rgb->color));
  EXPECT_EQ(from_rgb->color.type(), CV_8UC3);
}

TEST(FrameDecodeTest, Depth16IsScaledToMetresWithZeroAsNaN) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  for (double scale : {0.001, 0.0001}) {
    raw.depth_scale = scale;
    const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
    ASSERT_TRUE(frame.ok()) << frame.status();
    ASSERT_EQ(frame->depth.type(), CV_32FC1);
    EXPECT_EQ(frame->width(), kWidth);
    EXPECT_EQ(frame->height(), kHeight);
    EXPECT_TRUE(std::isnan(frame->depth.at<float>(0, 0)));
    // (u, v) = (3, 2): 500 + 9 + 22 = 531 units.
    EXPECT_FLOAT_EQ(frame->depth.at<float>(2, 3),
                    static_cast<float>(531 * scale));
    EXPECT_EQ(frame->intrinsics.fx, kKinectV1Intrinsics.fx);
  }
  raw.depth_scale = 0.0;  // the default, millimetres
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_FLOAT_EQ(frame->depth.at<float>(2, 3), 0.531f);
  // A scale that puts depths beyond kMaxDepthMetres makes them no data.
  raw.depth_scale = 1.0;
  const absl::StatusOr<RgbdFrame> far = DecodeFrame(raw, FrameLimits());
  ASSERT_FALSE(far.ok());  // every pixel is now > 100 m: no valid depth
  EXPECT_THAT(std::string(far.status().message()), HasSubstr("frame.depth"));
}

TEST(FrameDecodeTest, Depth32FKeepsMetresAndMarksInvalidAsNaN) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  cv::Mat depth(1, 6, CV_32FC1);
  const float values[] = {1.25f, kNaN, 0.0f, -2.0f, 3e38f, 0.5f};
  std::copy(std::begin(values), std::end(values), depth.ptr<float>(0));
  const std::string depth_bytes = Bytes(depth);
  const cv::Mat color = TestRgb(6, 1);
  const std::string color_bytes = Bytes(color);
  raw.color = RawFrom(color_bytes, color, "rgb8");
  raw.depth = RawFrom(depth_bytes, depth, "32FC1");
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(frame.ok()) << frame.status();
  const float* row = frame->depth.ptr<float>(0);
  EXPECT_EQ(row[0], 1.25f);
  for (int u = 1; u <= 4; ++u) EXPECT_TRUE(std::isnan(row[u])) << u;
  EXPECT_EQ(row[5], 0.5f);
}

TEST(FrameDecodeTest, RowPaddingIsHonoured) {
  const cv::Mat rgb = TestRgb(kWidth, kHeight);
  const cv::Mat depth = TestDepth16(kWidth, kHeight);
  // Odd padding: depth rows start at unaligned addresses.
  const uint32_t color_step = kWidth * 3 + 5;
  const uint32_t depth_step = kWidth * 2 + 3;
  std::string color_bytes(color_step * kHeight, '\xAB');
  std::string depth_bytes(depth_step * kHeight, '\xCD');
  for (int v = 0; v < kHeight; ++v) {
    std::memcpy(&color_bytes[v * color_step], rgb.ptr(v), kWidth * 3);
    std::memcpy(&depth_bytes[v * depth_step], depth.ptr(v), kWidth * 2);
  }
  // The last row needs no padding.
  color_bytes.resize(color_step * (kHeight - 1) + kWidth * 3);
  RawFrame raw;
  raw.color = RawFrom(color_bytes, rgb, "rgb8");
  raw.color.step = color_step;
  raw.depth = RawFrom(depth_bytes, depth, "16UC1");
  raw.depth.step = depth_step;
  raw.intrinsics = kKinectV1Intrinsics;
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_TRUE(SameImage(frame->color, rgb));
  cv::Mat expected(kHeight, kWidth, CV_32FC1);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const uint16_t units = depth.at<uint16_t>(v, u);
      expected.at<float>(v, u) =
          units == 0 ? kNaN : static_cast<float>(units * 0.001);
    }
  }
  ExpectSameDepth(frame->depth, expected);
}

TEST(FrameDecodeTest, PngFrameEqualsTheRawPath) {
  constexpr int kVgaWidth = 640;
  constexpr int kVgaHeight = 480;
  const cv::Mat rgb = TestRgb(kVgaWidth, kVgaHeight);
  const cv::Mat depth = TestDepth16(kVgaWidth, kVgaHeight);
  FrameBytes raw_bytes{Bytes(rgb), Bytes(depth)};
  RawFrame raw;
  raw.color = RawFrom(raw_bytes.color, rgb, "rgb8");
  raw.depth = RawFrom(raw_bytes.depth, depth, "16UC1");
  raw.intrinsics = kKinectV1Intrinsics;

  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  const std::string color_png = Encode(".png", bgr);
  const std::string depth_png = Encode(".png", depth);
  RawFrame png = raw;
  png.color = CompressedFrom(color_png);
  png.depth = CompressedFrom(depth_png);
  png.depth.encoding = "16UC1";  // agrees with the file
  png.depth.width = kVgaWidth;

  const absl::StatusOr<RgbdFrame> from_raw = DecodeFrame(raw, FrameLimits());
  const absl::StatusOr<RgbdFrame> from_png = DecodeFrame(png, FrameLimits());
  ASSERT_TRUE(from_raw.ok()) << from_raw.status();
  ASSERT_TRUE(from_png.ok()) << from_png.status();
  EXPECT_TRUE(SameImage(from_png->color, from_raw->color));
  ExpectSameDepth(from_png->depth, from_raw->depth);

  const double raw_ms =
      MedianMilliseconds(21, [&] { (void)DecodeFrame(raw, FrameLimits()); });
  const double png_ms =
      MedianMilliseconds(11, [&] { (void)DecodeFrame(png, FrameLimits()); });
  std::printf("DecodeFrame 640x480: raw %.2f ms, PNG %.2f ms (median)\n",
              raw_ms, png_ms);
}

TEST(FrameDecodeTest, JpegColourDecodesInRgbOrder) {
  // Left half red, right half blue (RGB), smooth enough for JPEG.
  cv::Mat rgb(32, 32, CV_8UC3, cv::Scalar(200, 30, 30));
  rgb(cv::Rect(16, 0, 16, 32)).setTo(cv::Scalar(30, 30, 200));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  const std::string jpeg = Encode(".jpg", bgr);
  const cv::Mat depth = TestDepth16(32, 32);
  const std::string depth_bytes = Bytes(depth);
  RawFrame raw;
  raw.color = CompressedFrom(jpeg);
  raw.color.encoding = "rgb8";
  raw.depth = RawFrom(depth_bytes, depth, "16UC1");
  raw.intrinsics = kKinectV1Intrinsics;
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(frame.ok()) << frame.status();
  ASSERT_EQ(frame->color.type(), CV_8UC3);
  cv::Mat diff;
  cv::absdiff(frame->color, rgb, diff);
  EXPECT_LT(cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2], 15.0);
  EXPECT_GT(frame->color.at<cv::Vec3b>(8, 4)[0], 150);   // red on the left
  EXPECT_GT(frame->color.at<cv::Vec3b>(8, 28)[2], 150);  // blue on the right
}

std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(FrameDecodeTest, DecodesTheOsdPngFrame) {
  const char* dir = std::getenv("FOVEA_OSD_DIR");
  const std::filesystem::path frames =
      std::filesystem::path(dir == nullptr ? "" : dir) / "frames";
  if (dir == nullptr || !std::filesystem::exists(frames / "learn6_color.png")) {
    GTEST_SKIP() << "FOVEA_OSD_DIR unset or without frames/learn6_*.png";
  }
  const std::string color = ReadFileBytes(frames / "learn6_color.png");
  const std::string depth = ReadFileBytes(frames / "learn6_depth_mm.png");
  RawFrame raw;
  raw.color = CompressedFrom(color);
  raw.depth = CompressedFrom(depth);
  raw.intrinsics = kKinectV1Intrinsics;
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_EQ(frame->width(), 640);
  EXPECT_EQ(frame->height(), 480);
  int valid = 0;
  for (int v = 0; v < frame->height(); ++v) {
    for (int u = 0; u < frame->width(); ++u) {
      const float z = frame->depth.at<float>(v, u);
      if (std::isnan(z)) continue;
      ++valid;
      ASSERT_GT(z, 0.2f);  // Kinect v1 range, metres
      ASSERT_LT(z, 10.0f);
    }
  }
  EXPECT_GT(valid, 640 * 480 / 2);
  const double ms =
      MedianMilliseconds(11, [&] { (void)DecodeFrame(raw, FrameLimits()); });
  std::printf("DecodeFrame OSD learn6 PNG pair: %.2f ms (median), %d valid\n",
              ms, valid);
}

}  // namespace
}  // namespace fovea
