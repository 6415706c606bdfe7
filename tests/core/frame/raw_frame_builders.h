// Frames made for the frame decoding tests (frame_decode_test.cc,
// frame_decode_refusal_test.cc): a valid 4 x 3 RawFrame and the images,
// bytes and files its parts are made of. OpenCV's encoder appears here
// only to make files: the shipped code does not link OpenCV's imgcodecs.

#ifndef FOVEA_TESTS_CORE_FRAME_RAW_FRAME_BUILDERS_H_
#define FOVEA_TESTS_CORE_FRAME_RAW_FRAME_BUILDERS_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/frame/frame_decode.h"
#include "core/frame/rgbd_frame.h"
#include "gtest/gtest.h"

namespace fovea::testing {

inline constexpr int kWidth = 4;
inline constexpr int kHeight = 3;

// Owns the bytes a RawFrame points into.
struct FrameBytes {
  std::string color;
  std::string depth;
};

// The pixels of `image`, row after row without padding.
inline std::string Bytes(const cv::Mat& image) {
  std::string bytes;
  const size_t row_bytes = image.cols * image.elemSize();
  for (int v = 0; v < image.rows; ++v) {
    bytes.append(image.ptr<char>(v), row_bytes);
  }
  return bytes;
}

// `image` as cv::imencode writes it (`extension` ".png" or ".jpg"); a
// test failure when it cannot.
inline std::string Encode(const std::string& extension, const cv::Mat& image) {
  std::vector<uchar> file;
  EXPECT_TRUE(cv::imencode(extension, image, file));
  return std::string(file.begin(), file.end());
}

// A colour image whose three channels differ everywhere.
inline cv::Mat TestRgb(int width, int height) {
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
inline cv::Mat TestDepth16(int width, int height) {
  cv::Mat depth(height, width, CV_16UC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      depth.at<uint16_t>(v, u) = static_cast<uint16_t>(500 + 3 * u + 11 * v);
    }
  }
  depth.at<uint16_t>(0, 0) = 0;
  return depth;
}

// A raw (uncompressed) image of `image`'s size in `encoding` over `bytes`,
// which must outlive it; rows unpadded.
inline RawImage RawFrom(const std::string& bytes, const cv::Mat& image,
                        std::string_view encoding) {
  RawImage raw;
  raw.width = image.cols;
  raw.height = image.rows;
  raw.encoding = encoding;
  raw.step = image.cols * image.elemSize();
  raw.data = bytes;
  return raw;
}

// A compressed image over `file` (PNG or JPEG), which must outlive it.
inline RawImage CompressedFrom(const std::string& file) {
  RawImage raw;
  raw.compressed = file;
  return raw;
}

// A valid 4 x 3 frame: rgb8 colour, 16UC1 depth, Kinect intrinsics.
inline RawFrame ValidFrame(FrameBytes& bytes) {
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

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_FRAME_RAW_FRAME_BUILDERS_H_
