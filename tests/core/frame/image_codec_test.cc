// The image codec: PNG round trips, every PNG layout and JPEG decoded as
// OpenCV decodes it, and the options. Hostile input is in
// image_codec_hostile_test.cc; the files both build and the checks both
// make are in image_builders.h and image_codec_test_util.h.

#include "core/frame/image_codec.h"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/frame/image_builders.h"
#include "tests/core/frame/image_codec_test_util.h"

namespace fovea {
namespace {

using ::fovea::testing::CmykJpeg;
using ::fovea::testing::Decode;
using ::fovea::testing::ExpectInvalid;
using ::fovea::testing::kField;
using ::fovea::testing::MakePng;
using ::fovea::testing::MaxDifference;
using ::fovea::testing::OpenCvDecode;
using ::fovea::testing::OpenCvEncode;
using ::fovea::testing::PngSpec;
using ::fovea::testing::RandomBytes;
using ::fovea::testing::RandomImage;
using ::fovea::testing::SmoothBgr;
using ::testing::HasSubstr;
using ::testing::StartsWith;

struct ModePair {
  ImageDecodeMode mode;
  int flags;
  const char* name;
};

constexpr ModePair kModes[] = {
    {ImageDecodeMode::kColor, cv::IMREAD_COLOR, "kColor"},
    {ImageDecodeMode::kGrey, cv::IMREAD_GRAYSCALE, "kGrey"},
    {ImageDecodeMode::kAnyDepth, cv::IMREAD_ANYDEPTH, "kAnyDepth"},
    {ImageDecodeMode::kUnchanged, cv::IMREAD_UNCHANGED, "kUnchanged"},
};

// Our decode against cv::imdecode's for every mode. Grey from colour is
// computed differently (cv::cvtColor here, libpng's rgb_to_gray there):
// allowed to differ by `grey_tolerance`.
void ExpectSameAsOpenCv(const std::string& file, const std::string& what,
                        double grey_tolerance) {
  for (const ModePair& mode : kModes) {
    const std::string context = what + ", " + mode.name;
    const absl::StatusOr<cv::Mat> ours = Decode(file, mode.mode);
    ASSERT_TRUE(ours.ok()) << context << ": " << ours.status();
    const cv::Mat theirs = OpenCvDecode(file, mode.flags);
    ASSERT_FALSE(theirs.empty()) << context;
    const bool converted = (mode.mode == ImageDecodeMode::kGrey ||
                            mode.mode == ImageDecodeMode::kAnyDepth) &&
                           grey_tolerance > 0.0;
    const double difference = MaxDifference(*ours, theirs);
    EXPECT_GE(difference, 0.0)
        << context << ": type " << ours->type() << " vs " << theirs.type()
        << ", " << ours->cols << "x" << ours->rows << " vs " << theirs.cols
        << "x" << theirs.rows;
    EXPECT_LE(difference, converted ? grey_tolerance : 0.0) << context;
  }
}

// ---------------------------------------------------------- round trips

TEST(ImageCodecTest, GreyPngRoundTripsExactly) {
  const cv::Mat grey = RandomImage(7, 13, CV_8UC1, 1);
  const absl::StatusOr<std::string> png = EncodePng(grey);
  ASSERT_TRUE(png.ok()) << png.status();
  for (ImageDecodeMode mode :
       {ImageDecodeMode::kGrey, ImageDecodeMode::kAnyDepth,
        ImageDecodeMode::kUnchanged}) {
    const absl::StatusOr<cv::Mat> decoded = Decode(*png, mode);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_EQ(MaxDifference(*decoded, grey), 0.0);
  }
  // And OpenCV reads what we wrote the same way.
  EXPECT_EQ(MaxDifference(OpenCvDecode(*png, cv::IMREAD_UNCHANGED), grey), 0.0);
}

TEST(ImageCodecTest, BgrPngRoundTripsExactlyAndIsRgbOnDisk) {
  const cv::Mat bgr = RandomImage(9, 11, CV_8UC3, 2);
  const absl::StatusOr<std::string> png = EncodePng(bgr);
  ASSERT_TRUE(png.ok()) << png.status();
  const absl::StatusOr<cv::Mat> decoded = Decode(*png, ImageDecodeMode::kColor);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(MaxDifference(*decoded, bgr), 0.0);
  // cv::imdecode takes the file as RGB and hands back BGR: the same image
  // only if we wrote RGB.
  EXPECT_EQ(MaxDifference(OpenCvDecode(*png, cv::IMREAD_COLOR), bgr), 0.0);
  // And we read OpenCV's PNG as it does.
  const absl::StatusOr<cv::Mat> from_opencv =
      Decode(OpenCvEncode(".png", bgr), ImageDecodeMode::kColor);
  ASSERT_TRUE(from_opencv.ok()) << from_opencv.status();
  EXPECT_EQ(MaxDifference(*from_opencv, bgr), 0.0);
}

TEST(ImageCodecTest, SixteenBitPngKeepsEveryValueExactly) {
  // 258 = 0x0102 tells a byte swap apart; no gamma maps 1 or 65534 to
  // themselves.
  cv::Mat depth(2, 4, CV_16UC1);
  const uint16_t kValues[] = {0, 1, 258, 65535, 256, 255, 32768, 65534};
  for (int i = 0; i < 8; ++i) depth.at<uint16_t>(i / 4, i % 4) = kValues[i];
  const absl::StatusOr<std::string> png = EncodePng(depth);
  ASSERT_TRUE(png.ok()) << png.status();
  for (ImageDecodeMode mode :
       {ImageDecodeMode::kAnyDepth, ImageDecodeMode::kUnchanged}) {
    const absl::StatusOr<cv::Mat> decoded = Decode(*png, mode);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    ASSERT_EQ(decoded->type(), CV_16UC1);
    for (int i = 0; i < 8; ++i) {
      EXPECT_EQ(decoded->at<uint16_t>(i / 4, i % 4), kValues[i]) << i;
    }
  }
  // Big-endian on disk: OpenCV reads the same values, and we read its file.
  EXPECT_EQ(MaxDifference(OpenCvDecode(*png, cv::IMREAD_ANYDEPTH), depth), 0.0);
  const absl::StatusOr<cv::Mat> from_opencv =
      Decode(OpenCvEncode(".png", depth), ImageDecodeMode::kAnyDepth);
  ASSERT_TRUE(from_opencv.ok()) << from_opencv.status();
  EXPECT_EQ(MaxDifference(*from_opencv, depth), 0.0);
  // kColor keeps the high byte, as IMREAD_COLOR does: 258 -> 1.
  const absl::StatusOr<cv::Mat> colour = Decode(*png, ImageDecodeMode::kColor);
  ASSERT_TRUE(colour.ok()) << colour.status();
  EXPECT_EQ(colour->at<cv::Vec3b>(0, 2), cv::Vec3b(1, 1, 1));
}

TEST(ImageCodecTest, EncodesANonContinuousImage) {
  const cv::Mat big = RandomImage(10, 10, CV_8UC3, 3);
  const cv::Mat roi = big(cv::Rect(2, 3, 5, 4));
  ASSERT_FALSE(roi.isContinuous());
  const absl::StatusOr<std::string> png = EncodePng(roi);
  ASSERT_TRUE(png.ok()) << png.status();
  const absl::StatusOr<cv::Mat> decoded = Decode(*png, ImageDecodeMode::kColor);
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(MaxDifference(*decoded, roi), 0.0);
}

TEST(ImageCodecTest, EncodesAtEveryCompressionLevel) {
  const cv::Mat grey = RandomImage(16, 16, CV_8UC1, 4);
  for (int level = 0; level <= 9; ++level) {
    PngEncodeOptions options;
    options.compression_level = level;
    const absl::StatusOr<std::string> png = EncodePng(grey, options);
    ASSERT_TRUE(png.ok()) << png.status();
    const absl::StatusOr<cv::Mat> decoded =
        Decode(*png, ImageDecodeMode::kUnchanged);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_EQ(MaxDifference(*decoded, grey), 0.0) << level;
  }
}

// ------------------------------------------------ PNG layouts vs OpenCV

TEST(ImageCodecTest, EveryPngLayoutDecodesAsOpenCvDoes) {
  struct Case {
    int bit_depth;
    int color_type;
    bool trns;
  };
  const Case kCases[] = {
      {1, 0, false},  {2, 0, false},  {4, 0, false}, {8, 0, false},
      {16, 0, false}, {8, 0, true},   {16, 0, true}, {8, 2, false},
      {16, 2, false}, {8, 2, true},   {1, 3, false}, {2, 3, false},
      {4, 3, false},  {8, 3, false},  {8, 3, true},  {4, 3, true},
      {8, 4, false},  {16, 4, false}, {8, 6, false}, {16, 6, false},
  };
  unsigned seed = 10;
  for (const Case& c : kCases) {
    PngSpec spec;
    spec.width = 13;
    spec.height = 5;
    spec.bit_depth = c.bit_depth;
    spec.color_type = c.color_type;
    if (c.color_type == 3) {
      const int entries = 1 << c.bit_depth;
      spec.plte = RandomBytes(3 * entries, seed++);
      if (c.trns) spec.trns = RandomBytes(entries / 2, seed++);
    } else if (c.trns) {
      // The transparent colour: a sample value per channel, 16 bits each.
      spec.trns = RandomBytes(c.color_type == 2 ? 6 : 2, seed++);
      if (c.bit_depth == 8) {
        for (size_t i = 0; i < spec.trns.size(); i += 2) spec.trns[i] = 0;
      }
    }
    const std::string png = MakePng(spec, seed++);
    // 16-bit colour to grey may round differently by a few units of 65535.
    ExpectSameAsOpenCv(png,
                       "bit depth " + std::to_string(c.bit_depth) +
                           ", colour type " + std::to_string(c.color_type) +
                           (c.trns ? " + tRNS" : ""),
                       c.bit_depth == 16 ? 4.0 : 1.0);
  }
}

TEST(ImageCodecTest, InterlacedPngDecodesAsOpenCvDoes) {
  for (const auto& [bit_depth, color_type] :
       {std::pair{8, 2}, std::pair{16, 0}, std::pair{8, 6}}) {
    PngSpec spec;
    spec.width = 11;  // odd sizes leave some Adam7 passes short
    spec.height = 9;
    spec.bit_depth = bit_depth;
    spec.color_type = color_type;
    spec.interlaced = true;
    ExpectSameAsOpenCv(MakePng(spec, 40 + bit_depth + color_type),
                       "interlaced, bit depth " + std::to_string(bit_depth) +
                           ", colour type " + std::to_string(color_type),
                       bit_depth == 16 ? 4.0 : 1.0);
  }
}

TEST(ImageCodecTest, DecodesTheOsdPngFrameAsOpenCvDoes) {
  const char* dir = std::getenv("FOVEA_OSD_DIR");
  const std::filesystem::path frames =
      std::filesystem::path(dir == nullptr ? "" : dir) / "frames";
  if (dir == nullptr || !std::filesystem::exists(frames / "learn6_color.png")) {
    GTEST_SKIP() << "FOVEA_OSD_DIR unset or without frames/learn6_*.png";
  }
  for (const char* name : {"learn6_color.png", "learn6_depth_mm.png"}) {
    std::ifstream in(frames / name, std::ios::binary);
    const std::string file(std::istreambuf_iterator<char>(in), {});
    ExpectSameAsOpenCv(file, name, 1.0);
  }
}

// ------------------------------------------------------------------ JPEG

TEST(ImageCodecTest, JpegDecodesAsOpenCvDoes) {
  const cv::Mat bgr = SmoothBgr(37, 45);  // not a multiple of the MCU
  cv::Mat grey;
  cv::extractChannel(bgr, grey, 1);
  const struct {
    std::string file;
    const char* what;
  } kFiles[] = {
      {OpenCvEncode(".jpg", bgr), "colour"},
      {OpenCvEncode(".jpg", bgr, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}),
       "progressive colour"},
      {OpenCvEncode(".jpg", bgr, {cv::IMWRITE_JPEG_QUALITY, 100}),
       "quality 100 colour"},
      {OpenCvEncode(".jpg", grey), "grey"},
  };
  for (const auto& file : kFiles) {
    for (const ModePair& mode : kModes) {
      const std::string context = std::string(file.what) + ", " + mode.name;
      const absl::StatusOr<cv::Mat> ours = Decode(file.file, mode.mode);
      ASSERT_TRUE(ours.ok()) << context << ": " << ours.status();
      const cv::Mat theirs = OpenCvDecode(file.file, mode.flags);
      const double difference = MaxDifference(*ours, theirs);
      EXPECT_GE(difference, 0.0) << context;
      EXPECT_LE(difference, 2.0) << context;
    }
  }
  const absl::StatusOr<cv::Mat> colour =
      Decode(kFiles[0].file, ImageDecodeMode::kColor);
  ASSERT_TRUE(colour.ok());
  cv::Mat error;
  cv::absdiff(*colour, bgr, error);
  EXPECT_LT(cv::norm(cv::mean(error), cv::NORM_INF), 4.0);  // still the image
}

TEST(ImageCodecTest, RefusesCmykJpeg) {
  const absl::StatusOr<cv::Mat> decoded =
      Decode(CmykJpeg(), ImageDecodeMode::kColor);
  ExpectInvalid(decoded, "CMYK");
  EXPECT_THAT(std::string(decoded.status().message()), HasSubstr("CMYK"));
}

// ---------------------------------------------------------------- options

TEST(ImageCodecTest, ValidatesOptions) {
  ImageDecodeOptions decode;
  decode.max_width = 0;
  EXPECT_THAT(std::string(DecodeImage("", decode, kField).status().message()),
              StartsWith("options.max_width:"));
  decode = ImageDecodeOptions();
  decode.max_height = kLargestDecodeSide + 1;
  EXPECT_THAT(std::string(Validate(decode).message()),
              StartsWith("options.max_height:"));

  PngEncodeOptions encode;
  encode.compression_level = 10;
  EXPECT_THAT(
      std::string(EncodePng(cv::Mat(2, 2, CV_8UC1), encode).status().message()),
      StartsWith("options.compression_level:"));
}

TEST(ImageCodecTest, RefusesToEncodeOtherTypes) {
  for (const cv::Mat& image : {cv::Mat(2, 2, CV_32FC1), cv::Mat(2, 2, CV_8UC4),
                               cv::Mat(2, 2, CV_16UC3), cv::Mat()}) {
    const absl::StatusOr<std::string> png = EncodePng(image);
    ASSERT_FALSE(png.ok());
    EXPECT_EQ(png.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(png.status().message()), StartsWith("image:"));
  }
}

}  // namespace
}  // namespace fovea
