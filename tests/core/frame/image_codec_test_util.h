// Decoding and its checks shared by the codec tests (image_codec_test.cc,
// image_codec_hostile_test.cc): DecodeImage in one mode with a known field
// name, OpenCV's decoder as the oracle (the shipped code does not link
// OpenCV's imgcodecs), and what a refusal must look like.

#ifndef FOVEA_TESTS_CORE_FRAME_IMAGE_CODEC_TEST_UTIL_H_
#define FOVEA_TESTS_CORE_FRAME_IMAGE_CODEC_TEST_UTIL_H_

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/image_codec.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea::testing {

// The field name Decode passes: every refusal's message starts with it.
inline constexpr char kField[] = "test.compressed";

// The default options with `mode`.
inline ImageDecodeOptions Mode(ImageDecodeMode mode) {
  ImageDecodeOptions options;
  options.mode = mode;
  return options;
}

// DecodeImage of `file` in `mode`, as field kField.
inline absl::StatusOr<cv::Mat> Decode(const std::string& file,
                                      ImageDecodeMode mode) {
  return DecodeImage(file, Mode(mode), kField);
}

// cv::imdecode of `file` with `flags`, EXIF orientation ignored as ours
// ignores it.
inline cv::Mat OpenCvDecode(const std::string& file, int flags) {
  return cv::imdecode(std::vector<uchar>(file.begin(), file.end()),
                      flags | cv::IMREAD_IGNORE_ORIENTATION);
}

// Largest absolute difference; -1 if type or size differ.
inline double MaxDifference(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != b.type() || a.size() != b.size()) return -1.0;
  return cv::norm(a, b, cv::NORM_INF);
}

// A refusal: INVALID_ARGUMENT with a message starting "<kField>:".
inline void ExpectInvalid(const absl::StatusOr<cv::Mat>& decoded,
                          const std::string& context) {
  ASSERT_FALSE(decoded.ok()) << context;
  EXPECT_EQ(decoded.status().code(), absl::StatusCode::kInvalidArgument)
      << context << ": " << decoded.status();
  EXPECT_THAT(std::string(decoded.status().message()),
              ::testing::StartsWith(std::string(kField) + ":"))
      << context;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_FRAME_IMAGE_CODEC_TEST_UTIL_H_
