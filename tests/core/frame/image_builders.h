// Images and image files made for the codec tests (image_codec_test.cc,
// image_codec_hostile_test.cc): random and smooth images, PNG files written
// byte by byte (every colour type, bit depth and interlacing, and headers
// that lie), a CMYK JPEG from libjpeg itself, and OpenCV's encoder, which
// appears here only as an oracle: the shipped code does not link OpenCV's
// imgcodecs.

#ifndef FOVEA_TESTS_CORE_FRAME_IMAGE_BUILDERS_H_
#define FOVEA_TESTS_CORE_FRAME_IMAGE_BUILDERS_H_

// jpeglib.h needs FILE and size_t declared first.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
// clang-format on
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "gtest/gtest.h"

namespace fovea::testing {

// `image` as cv::imencode writes it (`extension` ".png" or ".jpg"); a
// test failure when it cannot.
inline std::string OpenCvEncode(const std::string& extension,
                                const cv::Mat& image,
                                const std::vector<int>& params = {}) {
  std::vector<uchar> file;
  EXPECT_TRUE(cv::imencode(extension, image, file, params));
  return std::string(file.begin(), file.end());
}

// Uniform random samples over the whole range of `type`'s depth (8 or 16
// bits), the same for the same `seed`.
inline cv::Mat RandomImage(int rows, int cols, int type, unsigned seed) {
  cv::Mat image(rows, cols, type);
  cv::theRNG().state = seed;
  cv::randu(image, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

// Smooth enough for JPEG to keep it recognisable.
inline cv::Mat SmoothBgr(int rows, int cols) {
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

// ------------------------------------------------- hand-made PNG files

// PNG's pieces: big-endian integers, the CRC of a chunk's type and data, a
// whole chunk, and zlib's deflate at level 6.
inline void AppendBigEndian32(std::string& out, uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out.push_back(static_cast<char>((value >> shift) & 0xFF));
  }
}

inline uint32_t Crc(const std::string& bytes) {
  return static_cast<uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(bytes.data()),
            static_cast<uInt>(bytes.size())));
}

inline void AppendChunk(std::string& png, const std::string& type,
                        const std::string& data) {
  AppendBigEndian32(png, static_cast<uint32_t>(data.size()));
  const std::string body = type + data;
  png += body;
  AppendBigEndian32(png, Crc(body));
}

inline std::string Deflate(const std::string& raw) {
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

// Samples per pixel of a PNG colour type.
inline int Channels(int color_type) {
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
inline std::string MakePng(const PngSpec& spec, unsigned seed) {
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

// `count` random bytes, the same for the same `seed`.
inline std::string RandomBytes(size_t count, unsigned seed) {
  std::mt19937 random(seed);
  std::string bytes;
  for (size_t i = 0; i < count; ++i) bytes.push_back(random() & 0xFF);
  return bytes;
}

// The file with IHDR's width and height replaced and its CRC recomputed.
inline std::string WithPngSize(std::string png, uint32_t width,
                               uint32_t height) {
  std::string fields;
  AppendBigEndian32(fields, width);
  AppendBigEndian32(fields, height);
  png.replace(16, 8, fields);
  std::string crc;
  AppendBigEndian32(crc, Crc(png.substr(12, 17)));  // "IHDR" + 13 bytes
  png.replace(29, 4, crc);
  return png;
}

// ---------------------------------------------------------- a CMYK JPEG

// A 4 x 4 CMYK JPEG from libjpeg itself (OpenCV cannot write one).
inline std::string CmykJpeg() {
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

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_FRAME_IMAGE_BUILDERS_H_
