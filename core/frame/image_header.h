#ifndef FOVEA_CORE_FRAME_IMAGE_HEADER_H_
#define FOVEA_CORE_FRAME_IMAGE_HEADER_H_

// What a PNG or JPEG file is and what its header says, read by hand from
// the bytes: no libpng or libjpeg, nothing allocated, nothing decoded.
// DecodeImage (image_codec.h) tells the formats apart with IsPngFile and
// IsJpegFile; DecodeFrame (frame_decode.h) also reads the headers, to
// check a compressed image's size against its limits and against the
// width, height and step sent with it before the codec runs. The header
// read here is not checked further (CRCs, valid bit depths and colour
// types): the codec does that when it decodes.

#include <cstdint>
#include <string_view>

#include "absl/status/statusor.h"

namespace fovea {

// The eight bytes every PNG file starts with.
inline constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);

// Whether `file` starts with kPngSignature.
bool IsPngFile(std::string_view file);
// Whether `file` starts with a JPEG's start-of-image marker (FF D8).
bool IsJpegFile(std::string_view file);

// Width, height and sample layout from a compressed file's header.
struct ImageFileHeader {
  uint32_t width = 0;
  uint32_t height = 0;
  int bit_depth = 0;  // bits per sample
  int channels = 0;   // PNG: colour type; JPEG: number of components
};

// The IHDR chunk of a PNG file (which must start the file, after the
// signature; the signature itself is not checked). Too short a file or no
// IHDR first: INVALID_ARGUMENT "<field>: not a decodable PNG (no IHDR in
// <size> bytes)".
absl::StatusOr<ImageFileHeader> ReadPngFileHeader(std::string_view file,
                                                  std::string_view field);

// The first start-of-frame segment of a JPEG file, found by walking its
// markers from byte 2 (after FF D8, not checked). No frame header before
// the first scan, the end of image or the end of the file:
// INVALID_ARGUMENT "<field>: not a decodable JPEG (no frame header in
// <size> bytes)".
absl::StatusOr<ImageFileHeader> ReadJpegFileHeader(std::string_view file,
                                                   std::string_view field);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_IMAGE_HEADER_H_
