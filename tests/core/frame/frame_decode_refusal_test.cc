// DecodeFrame's refusals: every malformed, inconsistent or hostile frame
// (sizes, steps, encodings, intrinsics, depth scale, limits, compressed
// files that are cut, scrambled or lie about their size) is
// INVALID_ARGUMENT naming the field. What a valid frame decodes to is in
// frame_decode_test.cc.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <random>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/frame_decode.h"
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
using ::testing::StartsWith;

// A PNG signature and IHDR claiming `width` x `height`, with a bad CRC and
// no image data: only a reader of the header can size it.
std::string PngHeaderOnly(uint32_t width, uint32_t height, uint8_t bit_depth,
                          uint8_t color_type) {
  std::string file("\x89PNG\r\n\x1a\n", 8);
  file += std::string("\0\0\0\x0d", 4) + "IHDR";
  for (uint32_t value : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) {
      file.push_back(static_cast<char>((value >> shift) & 0xFF));
    }
  }
  file.push_back(static_cast<char>(bit_depth));
  file.push_back(static_cast<char>(color_type));
  file += std::string("\0\0\0", 3);            // compression, filter, interlace
  file += std::string("\xde\xad\xbe\xef", 4);  // CRC, deliberately wrong
  return file;
}

// Expects INVALID_ARGUMENT with a message starting "<field>:".
void ExpectInvalid(const RawFrame& raw, const std::string& field,
                   const FrameLimits& limits = FrameLimits()) {
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, limits);
  ASSERT_FALSE(frame.ok()) << "expected an error naming " << field;
  EXPECT_EQ(frame.status().code(), absl::StatusCode::kInvalidArgument)
      << frame.status();
  EXPECT_THAT(std::string(frame.status().message()), StartsWith(field + ":"))
      << frame.status();
}

// ---------------------------------------------------------------- refused

TEST(FrameDecodeTest, RefusesStepSmallerThanRow) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.color.step = kWidth * 3 - 1;
  ExpectInvalid(raw, "frame.color.step");
}

TEST(FrameDecodeTest, RefusesDataShorterThanRows) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth.data.remove_suffix(1);
  ExpectInvalid(raw, "frame.depth.data");
}

TEST(FrameDecodeTest, RefusesUnknownEncoding) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.color.encoding = "yuv422";
  ExpectInvalid(raw, "frame.color.encoding");
}

TEST(FrameDecodeTest, RefusesDepthEncodingInColour) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.color.encoding = "16UC1";
  raw.color.step = kWidth * 2;
  ExpectInvalid(raw, "frame.color.encoding");
}

TEST(FrameDecodeTest, RefusesColourEncodingInDepth) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth.encoding = "rgb8";
  ExpectInvalid(raw, "frame.depth.encoding");
}

TEST(FrameDecodeTest, RefusesMissingEncodingForRawData) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth.encoding = "";
  ExpectInvalid(raw, "frame.depth.encoding");
}

TEST(FrameDecodeTest, RefusesBigEndian) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth.is_bigendian = true;
  ExpectInvalid(raw, "frame.depth.is_bigendian");
}

TEST(FrameDecodeTest, RefusesColourAndDepthOfDifferentSizes) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth.width = kWidth - 1;
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  ExpectInvalid(raw, "frame.depth");
  EXPECT_THAT(std::string(frame.status().message()), HasSubstr("3 x 3"));
  EXPECT_THAT(std::string(frame.status().message()), HasSubstr("4 x 3"));
}

TEST(FrameDecodeTest, RefusesZeroFx) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.fx = 0.0;
  ExpectInvalid(raw, "frame.intrinsics.fx");
}

TEST(FrameDecodeTest, RefusesImplausiblyShortAndLongFocalLengths) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.fx = 1e-5;  // would spread a frame over kilometres
  ExpectInvalid(raw, "frame.intrinsics.fx");
  raw = ValidFrame(bytes);
  raw.intrinsics.fy = 1e9;
  ExpectInvalid(raw, "frame.intrinsics.fy");
}

TEST(FrameDecodeTest, RefusesNegativeFy) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.fy = -525.0;
  ExpectInvalid(raw, "frame.intrinsics.fy");
}

TEST(FrameDecodeTest, RefusesNaNCx) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.cx = std::nan("");
  ExpectInvalid(raw, "frame.intrinsics.cx");
}

TEST(FrameDecodeTest, RefusesInfiniteCy) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.cy = std::numeric_limits<double>::infinity();
  ExpectInvalid(raw, "frame.intrinsics.cy");
}

TEST(FrameDecodeTest, AcceptsNegativePrincipalPoint) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.intrinsics.cx = -10.0;
  EXPECT_TRUE(DecodeFrame(raw, FrameLimits()).ok());
}

TEST(FrameDecodeTest, RefusesNegativeDepthScale) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth_scale = -0.001;
  ExpectInvalid(raw, "frame.depth_scale");
}

TEST(FrameDecodeTest, RefusesNaNDepthScale) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth_scale = std::nan("");
  ExpectInvalid(raw, "frame.depth_scale");
}

TEST(FrameDecodeTest, RefusesRawFrameAboveTheLimit) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  FrameLimits limits;
  limits.max_width = kWidth - 1;
  ExpectInvalid(raw, "frame.color.width", limits);
  limits = FrameLimits();
  limits.max_height = kHeight - 1;
  ExpectInvalid(raw, "frame.color.height", limits);
}

TEST(FrameDecodeTest, RefusesHostileSizesWithoutOverflow) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.color.width = 4000000000u;
  raw.color.step = 4000000000u;
  ExpectInvalid(raw, "frame.color.width");

  raw = ValidFrame(bytes);
  // step * (height - 1) is 8.6e12: wraps in 32 bits, not in 64.
  raw.depth.step = 4294967295u;
  raw.depth.height = kHeight;
  ExpectInvalid(raw, "frame.depth.data");
}

TEST(FrameDecodeTest, RefusesPngWhoseHeaderClaims60000Square) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const std::string color_png = PngHeaderOnly(60000, 60000, 8, 2);
  raw.color = CompressedFrom(color_png);
  ExpectInvalid(raw, "frame.color.width");
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  EXPECT_THAT(std::string(frame.status().message()), HasSubstr("60000"));

  raw = ValidFrame(bytes);
  const std::string depth_png = PngHeaderOnly(640, 60000, 16, 0);
  raw.depth = CompressedFrom(depth_png);
  ExpectInvalid(raw, "frame.depth.height");
}

TEST(FrameDecodeTest, RefusesDepthWithoutAValidPixel) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  std::fill(bytes.depth.begin(), bytes.depth.end(), '\0');
  ExpectInvalid(raw, "frame.depth");
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  EXPECT_THAT(std::string(frame.status().message()),
              HasSubstr("no valid depth pixel"));
}

TEST(FrameDecodeTest, RefusesTruncatedPng) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const std::string png = Encode(".png", TestRgb(64, 48));
  const std::string truncated = png.substr(0, png.size() / 2);
  const cv::Mat depth = TestDepth16(64, 48);
  const std::string depth_bytes = Bytes(depth);
  raw.color = CompressedFrom(truncated);
  raw.depth = RawFrom(depth_bytes, depth, "16UC1");
  ExpectInvalid(raw, "frame.color.compressed");

  // Cut inside the IHDR chunk: not even a header.
  const std::string stub = png.substr(0, 20);
  raw.color = CompressedFrom(stub);
  ExpectInvalid(raw, "frame.color.compressed");
}

TEST(FrameDecodeTest, RefusesRandomBytesAsJpeg) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  std::mt19937 random(7);
  std::string jpeg("\xff\xd8\xff", 3);
  for (int i = 0; i < 2000; ++i) jpeg.push_back(static_cast<char>(random()));
  raw.color = CompressedFrom(jpeg);
  ExpectInvalid(raw, "frame.color.compressed");

  std::string noise;
  for (int i = 0; i < 2000; ++i) noise.push_back(static_cast<char>(random()));
  raw.color = CompressedFrom(noise);
  ExpectInvalid(raw, "frame.color.compressed");
}

TEST(FrameDecodeTest, RefusesJpegWithValidHeaderAndGarbageData) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  std::string jpeg = Encode(".jpg", TestRgb(kWidth, kHeight));
  // Keep the headers, scramble everything after the middle.
  for (size_t i = jpeg.size() / 2; i + 2 < jpeg.size(); ++i) jpeg[i] ^= 0x5A;
  jpeg.resize(jpeg.size() - 2);  // and drop the end-of-image marker
  raw.color = CompressedFrom(jpeg);
  const absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits());
  // libjpeg may salvage a damaged scan; it must never crash, and an error
  // must name the field.
  if (!frame.ok()) ExpectInvalid(raw, "frame.color.compressed");
}

TEST(FrameDecodeTest, RefusesEightBitPngAsDepth) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  cv::Mat grey(kHeight, kWidth, CV_8UC1, cv::Scalar(100));
  const std::string png = Encode(".png", grey);
  raw.depth = CompressedFrom(png);
  ExpectInvalid(raw, "frame.depth.compressed");
}

TEST(FrameDecodeTest, RefusesJpegAsDepth) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const std::string jpeg =
      Encode(".jpg", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(100)));
  raw.depth = CompressedFrom(jpeg);
  ExpectInvalid(raw, "frame.depth.compressed");
}

TEST(FrameDecodeTest, RefusesDataAndCompressedBothSet) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const std::string png = Encode(".png", TestRgb(kWidth, kHeight));
  raw.color.compressed = png;
  ExpectInvalid(raw, "frame.color.data");
}

TEST(FrameDecodeTest, RefusesImageWithNeitherDataNorCompressed) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  raw.depth = RawImage();
  ExpectInvalid(raw, "frame.depth.data");
}

TEST(FrameDecodeTest, RefusesCompressedWhoseFieldsDisagreeWithTheFile) {
  FrameBytes bytes;
  RawFrame raw = ValidFrame(bytes);
  const std::string png = Encode(".png", TestRgb(kWidth, kHeight));
  raw.color = CompressedFrom(png);
  raw.color.width = kWidth + 1;
  ExpectInvalid(raw, "frame.color.width");

  raw.color = CompressedFrom(png);
  raw.color.encoding = "16UC1";
  ExpectInvalid(raw, "frame.color.encoding");

  const std::string depth_png = Encode(".png", TestDepth16(kWidth, kHeight));
  raw = ValidFrame(bytes);
  raw.depth = CompressedFrom(depth_png);
  raw.depth.encoding = "32FC1";
  ExpectInvalid(raw, "frame.depth.encoding");
}

TEST(FrameDecodeTest, ValidatesLimits) {
  FrameLimits limits;
  EXPECT_TRUE(Validate(limits).ok());
  limits.max_height = 0;
  EXPECT_THAT(std::string(Validate(limits).message()),
              StartsWith("limits.max_height:"));
}

}  // namespace
}  // namespace fovea
