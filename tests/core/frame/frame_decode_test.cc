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
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kWidth = 4;
constexpr int kHeight = 3;

// Owns the bytes a RawFrame points into.
struct FrameBytes {
  std::string color;
  std::string depth;
};

std::string Bytes(const cv::Mat& image) {
  std::string bytes;
  const size_t row_bytes = image.cols * image.elemSize();
  for (int v = 0; v < image.rows; ++v) {
    bytes.append(image.ptr<char>(v), row_bytes);
  }
  return bytes;
}

std::string Encode(const std::string& extension, const cv::Mat& image) {
  std::vector<uchar> file;
  EXPECT_TRUE(cv::imencode(extension, image, file));
  return std::string(file.begin(), file.end());
}

// A colour image whose three channels differ everywhere.
cv::Mat TestRgb(int width, int height) {
  cv::Mat rgb(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uchar>(u * 7 + v),
                                          static_cast<uchar>(100 + u + 3 * v),
                                          static_cast<uchar>(250 - u - v * 5));
    }
  }
  return rgb;
}

// 16-bit depth in millimetres-like units with a hole at (0, 0).
cv::Mat TestDepth16(int width, int height) {
  cv::Mat depth(height, width, CV_16UC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      depth.at<uint16_t>(v, u) = static_cast<uint16_t>(500 + 3 * u + 11 * v);
    }
  }
  depth.at<uint16_t>(0, 0) = 0;
  return depth;
}

RawImage RawFrom(const std::string& bytes, const cv::Mat& image,
                 std::string_view encoding) {
  RawImage raw;
  raw.width = image.cols;
  raw.height = image.rows;
  raw.encoding = encoding;
  raw.step = image.cols * image.elemSize();
  raw.data = bytes;
  return raw;
}

RawImage CompressedFrom(const std::string& file) {
  RawImage raw;
  raw.compressed = file;
  return raw;
}

// A valid 4 x 3 frame: rgb8 colour, 16UC1 depth, Kinect intrinsics.
RawFrame ValidFrame(FrameBytes& bytes) {
  const cv::Mat rgb = TestRgb(kWidth, kHeight);
  const cv::Mat depth = TestDepth16(kWidth, kHeight);
  bytes.color = Bytes(rgb);
  bytes.depth = Bytes(depth);
  RawFrame raw;
  raw.color = RawFrom(bytes.color, rgb, "rgb8");
  raw.depth = RawFrom(bytes.depth, depth, "16UC1");
  raw.intrinsics = kKinectV1Intrinsics;
  raw.depth_scale = 0.001;
  return raw;
}

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
