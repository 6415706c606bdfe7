#include "core/frame/image_codec.h"

// jpeglib.h needs FILE and size_t declared first.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
// clang-format on
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

// cv::imencode / cv::imdecode appear here only as an oracle: the shipped
// code does not link OpenCV's imgcodecs.

namespace fovea {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr char kField[] = "test.compressed";

ImageDecodeOptions Mode(ImageDecodeMode mode) {
  ImageDecodeOptions options;
  options.mode = mode;
  return options;
}

absl::StatusOr<cv::Mat> Decode(const std::string& file, ImageDecodeMode mode) {
  return DecodeImage(file, Mode(mode), kField);
}

cv::Mat OpenCvDecode(const std::string& file, int flags) {
  return cv::imdecode(std::vector<uchar>(file.begin(), file.end()),
                      flags | cv::IMREAD_IGNORE_ORIENTATION);
}

std::string OpenCvEncode(const std::string& extension, const cv::Mat& image,
                         const std::vector<int>& params = {}) {
  std::vector<uchar> file;
  EXPECT_TRUE(cv::imencode(extension, image, file, params));
  return std::string(file.begin(), file.end());
}

// Largest absolute difference; -1 if type or size differ.
double MaxDifference(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != b.type() || a.size() != b.size()) return -1.0;
  return cv::norm(a, b, cv::NORM_INF);
}

cv::Mat RandomImage(int rows, int cols, int type, unsigned seed) {
  cv::Mat image(rows, cols, type);
  cv::theRNG().state = seed;
  cv::randu(image, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

void ExpectInvalid(const absl::StatusOr<cv::Mat>& decoded,
                   const std::string& context) {
  ASSERT_FALSE(decoded.ok()) << context;
  EXPECT_EQ(decoded.status().code(), absl::StatusCode::kInvalidArgument)
      << context << ": " << decoded.status();
  EXPECT_THAT(std::string(decoded.status().message()),
              StartsWith(std::string(kField) + ":"))
      << context;
}

// ------------------------------------------------- hand-made PNG files

void AppendBigEndian32(std::string& out, uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out.push_back(static_cast<char>((value >> shift) & 0xFF));
  }
}

uint32_t Crc(const std::string& bytes) {
  return static_cast<uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(bytes.data()),
            static_cast<uInt>(bytes.size())));
}

void AppendChunk(std::string& png, const std::string& type,
                 const std::string& data) {
  AppendBigEndian32(png, static_cast<uint32_t>(data.size()));
  const std::string body = type + data;
  png += body;
  AppendBigEndian32(png, Crc(body));
}

std::string Deflate(const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                      reinterpret_cast<const Bytef*>(raw.data()),
                      static_cast<uLong>(raw.size()), 6),
            Z_OK);
  out.resize(size);
  return out;
}

struct PngSpec {
  int width = 5;
  int height = 4;
  int bit_depth = 8;
  int color_type = 0;       // 0 grey, 2 RGB, 3 palette, 4 grey + alpha, 6 RGBA
  bool interlaced = false;  // Adam7; bit_depth 8 or 16 only
  int data_rows = -1;       // rows in IDAT if >= 0 (non-interlaced only)
  std::string plte;
  std::string trns;
};

int Channels(int color_type) {
  switch (color_type) {
    case 2:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return 1;
  }
}

// A PNG of random samples (palette indices within the palette), written
// byte by byte so every colour type, bit depth and interlacing is covered.
std::string MakePng(const PngSpec& spec, unsigned seed) {
  std::mt19937 random(seed);
  const int bits_per_pixel = spec.bit_depth * Channels(spec.color_type);
  const int row_bytes = (spec.width * bits_per_pixel + 7) / 8;
  std::vector<std::string> rows(spec.height);
  for (std::string& row : rows) {
    for (int i = 0; i < row_bytes; ++i) row.push_back(random() & 0xFF);
  }
  std::string raw;
  if (!spec.interlaced) {
    const int data_rows = spec.data_rows >= 0 ? spec.data_rows : spec.height;
    for (int v = 0; v < data_rows; ++v) raw += '\0' + rows[v];
  } else {
    const int bytes_per_pixel = bits_per_pixel / 8;
    constexpr int kPasses[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8},
                                   {2, 0, 4, 4}, {0, 2, 2, 4}, {1, 0, 2, 2},
                                   {0, 1, 1, 2}};
    for (const auto& pass : kPasses) {
      if (pass[0] >= spec.width) continue;
      for (int y = pass[1]; y < spec.height; y += pass[3]) {
        raw += '\0';
        for (int x = pass[0]; x < spec.width; x += pass[2]) {
          raw += rows[y].substr(x * bytes_per_pixel, bytes_per_pixel);
        }
      }
    }
  }
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  AppendBigEndian32(ihdr, spec.width);
  AppendBigEndian32(ihdr, spec.height);
  ihdr += static_cast<char>(spec.bit_depth);
  ihdr += static_cast<char>(spec.color_type);
  ihdr += std::string("\0\0", 2);
  ihdr += static_cast<char>(spec.interlaced ? 1 : 0);
  AppendChunk(png, "IHDR", ihdr);
  if (!spec.plte.empty()) AppendChunk(png, "PLTE", spec.plte);
  if (!spec.trns.empty()) AppendChunk(png, "tRNS", spec.trns);
  AppendChunk(png, "IDAT", Deflate(raw));
  AppendChunk(png, "IEND", "");
  return png;
}

std::string RandomBytes(size_t count, unsigned seed) {
  std::mt19937 random(seed);
  std::string bytes;
  for (size_t i = 0; i < count; ++i) bytes.push_back(random() & 0xFF);
  return bytes;
}

// The file with IHDR's width and height replaced and its CRC recomputed.
std::string WithPngSize(std::string png, uint32_t width, uint32_t height) {
  std::string fields;
  AppendBigEndian32(fields, width);
  AppendBigEndian32(fields, height);
  png.replace(16, 8, fields);
  std::string crc;
  AppendBigEndian32(crc, Crc(png.substr(12, 17)));  // "IHDR" + 13 bytes
  png.replace(29, 4, crc);
  return png;
}

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

// Smooth enough for JPEG to keep it recognisable.
cv::Mat SmoothBgr(int rows, int cols) {
  cv::Mat bgr(rows, cols, CV_8UC3);
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      bgr.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<uchar>(4 * u), static_cast<uchar>(200 - 3 * v),
                    static_cast<uchar>(2 * (u + v)));
    }
  }
  return bgr;
}

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

// A 4 x 4 CMYK JPEG from libjpeg itself (OpenCV cannot write one).
std::string CmykJpeg() {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr errors;
  cinfo.err = jpeg_std_error(&errors);
  jpeg_create_compress(&cinfo);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = 4;
  cinfo.image_height = 4;
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_start_compress(&cinfo, TRUE);
  unsigned char row[16] = {};
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW rows[1] = {row};
    jpeg_write_scanlines(&cinfo, rows, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::string file(reinterpret_cast<char*>(buffer), size);
  std::free(buffer);
  return file;
}

TEST(ImageCodecTest, RefusesCmykJpeg) {
  const absl::StatusOr<cv::Mat> decoded =
      Decode(CmykJpeg(), ImageDecodeMode::kColor);
  ExpectInvalid(decoded, "CMYK");
  EXPECT_THAT(std::string(decoded.status().message()), HasSubstr("CMYK"));
}

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
