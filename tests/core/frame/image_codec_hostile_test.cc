// The image codec on hostile input: truncated files, headers beyond the
// limits, compression bombs, garbage and files missing pixels are refused
// with INVALID_ARGUMENT naming the field, before allocating what they
// claim; a long decode stops at its interrupt. The files are built in
// image_builders.h.

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/image_codec.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/frame/image_builders.h"
#include "tests/core/frame/image_codec_test_util.h"

namespace fovea {
namespace {

using ::fovea::testing::AppendChunk;
using ::fovea::testing::Decode;
using ::fovea::testing::Deflate;
using ::fovea::testing::ExpectInvalid;
using ::fovea::testing::kField;
using ::fovea::testing::MakePng;
using ::fovea::testing::OpenCvEncode;
using ::fovea::testing::PngSpec;
using ::fovea::testing::RandomBytes;
using ::fovea::testing::RandomImage;
using ::fovea::testing::SmoothBgr;
using ::fovea::testing::WithPngSize;
using ::testing::HasSubstr;

// ------------------------------------------------------- hostile input

TEST(ImageCodecTest, EveryTruncatedPngIsAnError) {
  const absl::StatusOr<std::string> png =
      EncodePng(RandomImage(24, 32, CV_8UC3, 5));
  ASSERT_TRUE(png.ok());
  for (size_t size = 0; size < png->size(); ++size) {
    ExpectInvalid(Decode(png->substr(0, size), ImageDecodeMode::kColor),
                  "PNG cut to " + std::to_string(size) + " bytes");
  }
  PngSpec spec;
  spec.width = 11;
  spec.height = 9;
  spec.color_type = 2;
  spec.interlaced = true;
  const std::string interlaced = MakePng(spec, 6);
  for (size_t size = 0; size < interlaced.size(); ++size) {
    ExpectInvalid(Decode(interlaced.substr(0, size), ImageDecodeMode::kColor),
                  "interlaced PNG cut to " + std::to_string(size) + " bytes");
  }
}

TEST(ImageCodecTest, EveryTruncatedJpegIsAnError) {
  const cv::Mat bgr = SmoothBgr(24, 32);
  for (const std::string& jpeg :
       {OpenCvEncode(".jpg", bgr),
        OpenCvEncode(".jpg", bgr, {cv::IMWRITE_JPEG_PROGRESSIVE, 1})}) {
    ASSERT_TRUE(Decode(jpeg, ImageDecodeMode::kColor).ok());
    for (size_t size = 0; size < jpeg.size(); ++size) {
      ExpectInvalid(Decode(jpeg.substr(0, size), ImageDecodeMode::kColor),
                    "JPEG cut to " + std::to_string(size) + " bytes");
    }
  }
}

TEST(ImageCodecTest, RefusesAPngHeaderBeyondTheLimitBeforeAllocating) {
  const absl::StatusOr<std::string> png =
      EncodePng(cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)));
  ASSERT_TRUE(png.ok());
  // A valid CRC, so only the size check can refuse it: 100000 x 100000 RGB
  // would be 30 GB.
  const std::string huge = WithPngSize(*png, 100000, 100000);
  ASSERT_LT(huge.size(), 1024u);
  ImageDecodeOptions options;
  options.max_width = 640;
  options.max_height = 480;
  absl::StatusOr<cv::Mat> decoded = DecodeImage(huge, options, kField);
  ExpectInvalid(decoded, "huge PNG");
  EXPECT_THAT(std::string(decoded.status().message()),
              HasSubstr("width 100000 exceeds the limit of 640"));

  options.max_width = kLargestDecodeSide;
  decoded = DecodeImage(WithPngSize(*png, 600, 100000), options, kField);
  ExpectInvalid(decoded, "tall PNG");
  EXPECT_THAT(std::string(decoded.status().message()),
              HasSubstr("height 100000 exceeds the limit of 480"));

  // The size check is the only thing wrong with it: within the limits, the
  // patched header decodes to its (unchanged) 4 x 4 pixels.
  decoded = DecodeImage(WithPngSize(*png, 4, 4), options, kField);
  EXPECT_TRUE(decoded.ok()) << decoded.status();
}

TEST(ImageCodecTest, RefusesAJpegHeaderBeyondTheLimit) {
  std::string jpeg = OpenCvEncode(".jpg", SmoothBgr(8, 8));
  const size_t sof = jpeg.find("\xff\xc0");
  ASSERT_NE(sof, std::string::npos);
  jpeg.replace(sof + 5, 4, std::string("\xea\x60\xea\x60", 4));  // 60000^2
  ImageDecodeOptions options;
  options.max_width = 640;
  options.max_height = 480;
  const absl::StatusOr<cv::Mat> decoded = DecodeImage(jpeg, options, kField);
  ExpectInvalid(decoded, "huge JPEG");
  EXPECT_THAT(std::string(decoded.status().message()),
              HasSubstr("width 60000 exceeds the limit of 640"));
}

// 300 zTXt chunks, each 1 MB of text when inflated (300 MB in all, 300 kB
// of file), before the pixels: skipped unread (inflating them took 14 s
// for 200 chunks of 7.8 MB), and the pixels come out as without them.
TEST(ImageCodecTest, CompressedTextChunksAreSkippedAndThePixelsDecode) {
  PngSpec spec;
  spec.width = 16;
  spec.height = 8;
  const std::string plain = MakePng(spec, 7);
  const size_t idat = plain.find("IDAT") - 4;
  std::string text("comment\0\0", 9);
  text += Deflate(std::string(1 << 20, 'a'));
  std::string chunks;
  for (int i = 0; i < 300; ++i) AppendChunk(chunks, "zTXt", text);
  const std::string bomb = plain.substr(0, idat) + chunks + plain.substr(idat);
  absl::StatusOr<cv::Mat> expected = Decode(plain, ImageDecodeMode::kGrey);
  absl::StatusOr<cv::Mat> decoded = Decode(bomb, ImageDecodeMode::kGrey);
  ASSERT_TRUE(expected.ok()) << expected.status();
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(cv::norm(*expected, *decoded, cv::NORM_INF), 0.0);
}

// A zlib stream holding far more rows than IHDR declares (the rest
// inflates to gigabytes in the attack): refused once the declared rows are
// read, before the rest is inflated.
TEST(ImageCodecTest, CompressedRowsBeyondTheDeclaredHeightAreRefused) {
  PngSpec spec;
  spec.width = 8;
  spec.height = 40000;  // random rows: 360 kB of deflate after the first 4
  const std::string png = WithPngSize(MakePng(spec, 3), 8, 4);
  absl::StatusOr<cv::Mat> decoded = Decode(png, ImageDecodeMode::kGrey);
  EXPECT_EQ(decoded.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(decoded.status().message(),
              HasSubstr("more compressed image data than the declared rows"));
  // One row more than declared is within the slack.
  spec.height = 5;
  EXPECT_TRUE(
      Decode(WithPngSize(MakePng(spec, 3), 8, 4), ImageDecodeMode::kGrey).ok());
}

// The decoder checks the interrupt every 64 rows and returns its error.
TEST(ImageCodecTest, APngDecodeStopsAtTheInterrupt) {
  PngSpec spec;
  spec.width = 32;
  spec.height = 300;
  const std::string png = MakePng(spec, 5);
  ImageDecodeOptions options;
  options.mode = ImageDecodeMode::kGrey;
  int checks = 0;
  options.interrupt = [&checks] {
    return ++checks < 3 ? absl::OkStatus()
                        : absl::DeadlineExceededError("too late");
  };
  absl::StatusOr<cv::Mat> decoded = DecodeImage(png, options, kField);
  EXPECT_EQ(decoded.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(checks, 3);
  options.interrupt = [&checks] {
    ++checks;
    return absl::OkStatus();
  };
  checks = 0;
  EXPECT_TRUE(DecodeImage(png, options, kField).ok());
  EXPECT_EQ(checks, 5);  // rows 0, 64, 128, 192, 256
}

TEST(ImageCodecTest, RefusesGarbage) {
  ExpectInvalid(Decode("", ImageDecodeMode::kColor), "empty");
  ExpectInvalid(Decode(RandomBytes(3000, 7), ImageDecodeMode::kColor),
                "random bytes");
  ExpectInvalid(
      Decode(std::string("\x89PNG\r\n\x1a\n", 8) + RandomBytes(3000, 8),
             ImageDecodeMode::kColor),
      "PNG signature, then random bytes");
  ExpectInvalid(Decode(std::string("\xff\xd8\xff", 3) + RandomBytes(3000, 9),
                       ImageDecodeMode::kColor),
                "JPEG SOI, then random bytes");

  // One flipped bit in the image data: the IDAT CRC no longer matches.
  const absl::StatusOr<std::string> png =
      EncodePng(RandomImage(8, 8, CV_8UC1, 10));
  ASSERT_TRUE(png.ok());
  std::string flipped = *png;
  const size_t idat = flipped.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  flipped[idat + 8] ^= 0x01;
  ExpectInvalid(Decode(flipped, ImageDecodeMode::kUnchanged), "flipped bit");

  // JPEG entropy data scrambled: libjpeg warns, and a warning is an error.
  std::string jpeg = OpenCvEncode(".jpg", SmoothBgr(32, 32));
  const size_t sos = jpeg.find("\xff\xda");
  ASSERT_NE(sos, std::string::npos);
  for (size_t i = sos + 20; i + 2 < jpeg.size(); ++i) jpeg[i] ^= 0x5A;
  ExpectInvalid(Decode(jpeg, ImageDecodeMode::kColor), "scrambled JPEG");
}

TEST(ImageCodecTest, RefusesWellFormedFilesWithMissingPixels) {
  // Every chunk and CRC valid, but IDAT holds 3 of the 4 rows IHDR claims.
  PngSpec spec;
  spec.color_type = 2;
  spec.data_rows = 3;
  ExpectInvalid(Decode(MakePng(spec, 11), ImageDecodeMode::kColor),
                "PNG with a row missing");
  spec.data_rows = -1;
  ASSERT_TRUE(Decode(MakePng(spec, 11), ImageDecodeMode::kColor).ok());

  // The scan cut in the middle, then a proper end-of-image marker.
  const std::string jpeg = OpenCvEncode(".jpg", SmoothBgr(64, 64));
  const size_t sos = jpeg.find("\xff\xda");
  ASSERT_NE(sos, std::string::npos);
  const std::string cut =
      jpeg.substr(0, (sos + jpeg.size()) / 2) + std::string("\xff\xd9", 2);
  ExpectInvalid(Decode(cut, ImageDecodeMode::kColor), "JPEG with half a scan");
}

}  // namespace
}  // namespace fovea
