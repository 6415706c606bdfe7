#ifndef FOVEA_CORE_FRAME_IMAGE_CODEC_H_
#define FOVEA_CORE_FRAME_IMAGE_CODEC_H_

// PNG and JPEG files to and from cv::Mat, with libpng and libjpeg-turbo
// only: the replacement for OpenCV's imgcodecs (cv::imdecode /
// cv::imencode), whose shared-library closure (GDAL, OpenEXR, poppler, ...)
// is most of a server image. Decoding gives what cv::imdecode gives for the
// matching IMREAD_* flag (with IMREAD_IGNORE_ORIENTATION), except where a
// comment below says otherwise.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/base/interrupt.h"

namespace fovea {

// What DecodeImage returns; each mode is named after the cv::imdecode flag
// whose output it reproduces.
enum class ImageDecodeMode {
  // cv::IMREAD_COLOR: CV_8UC3 in B, G, R order. Grey is replicated, alpha
  // and tRNS transparency are dropped (not composited), palettes expanded,
  // 16-bit PNG samples reduced to their high byte.
  kColor,
  // cv::IMREAD_GRAYSCALE: CV_8UC1. A colour PNG is converted with
  // cv::COLOR_BGR2GRAY (OpenCV asks libpng; they may differ by 1); a colour
  // JPEG gives its luma, as with OpenCV.
  kGrey,
  // cv::IMREAD_ANYDEPTH: one channel as kGrey, but a 16-bit PNG stays
  // CV_16UC1 (depth images).
  kAnyDepth,
  // cv::IMREAD_UNCHANGED: the file's own layout. PNG: CV_8U or CV_16U with
  // 1 channel (grey; tRNS ignored), 3 (BGR: RGB, or a palette without
  // tRNS) or 4 (BGRA: RGBA, grey + alpha, or RGB / palette with tRNS).
  // JPEG: CV_8UC1 for a one-component file, else CV_8UC3 BGR.
  kUnchanged,
};

// Largest ImageDecodeOptions::max_width / max_height accepted: keeps every
// row and image byte count of a cv::Mat well inside its int and size_t.
inline constexpr uint32_t kLargestDecodeSide = 1u << 16;

struct ImageDecodeOptions {
  ImageDecodeMode mode = ImageDecodeMode::kColor;  // see ImageDecodeMode
  // Pixels; a file whose header is wider or taller is refused before any
  // pixel buffer is allocated. In [1, kLargestDecodeSide].
  uint32_t max_width = 1920;
  uint32_t max_height = 1080;
  // Checked every 64 rows of a PNG (whose decoding time a file can stretch
  // far beyond its size); its error is returned as is. May be empty. A
  // JPEG's work is bounded by its size and kMaxJpegScans.
  InterruptCheck interrupt;
};

absl::Status Validate(const ImageDecodeOptions& options);

// Decodes a PNG or a JPEG file (told apart by their signatures) held in
// `file`. 16-bit PNG samples come out in host byte order, exactly as
// stored: no gamma, colour-profile or EXIF-orientation handling. JPEG:
// grey, YCbCr and RGB files; CMYK / YCCK are refused.
// On return the image is complete: truncated or corrupt data, a libjpeg
// warning about the data ("Corrupt JPEG data: ...", premature end of
// file), a missing PNG IEND, or a header beyond max_width x max_height is
// INVALID_ARGUMENT with a message starting "<field>: " (e.g.
// "frame.color.compressed: not a decodable PNG (812 bytes; libpng: ...)").
// Invalid options are INVALID_ARGUMENT naming "options.<field>"; a failed
// allocation is RESOURCE_EXHAUSTED. Never throws, never calls exit().
absl::StatusOr<cv::Mat> DecodeImage(std::string_view file,
                                    const ImageDecodeOptions& options,
                                    std::string_view field);

struct PngEncodeOptions {
  // zlib level in [0, 9]. 1 (Z_BEST_SPEED) with the SUB filter and the
  // Z_RLE strategy is what cv::imencode(".png") does by default.
  int compression_level = 1;
};

absl::Status Validate(const PngEncodeOptions& options);

// Encodes a non-empty CV_8UC1 (grey), CV_8UC3 (B, G, R in memory, RGB in
// the file) or CV_16UC1 (host order in memory, big-endian in the file)
// image, continuous or not, as a non-interlaced PNG without gamma or
// colour-profile chunks. Other types or an empty image: INVALID_ARGUMENT
// naming "image"; invalid options: INVALID_ARGUMENT naming
// "options.<field>"; a libpng failure: INTERNAL.
absl::StatusOr<std::string> EncodePng(
    const cv::Mat& image, const PngEncodeOptions& options = PngEncodeOptions());

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_IMAGE_CODEC_H_
