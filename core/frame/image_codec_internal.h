#ifndef FOVEA_CORE_FRAME_IMAGE_CODEC_INTERNAL_H_
#define FOVEA_CORE_FRAME_IMAGE_CODEC_INTERNAL_H_

// What the pieces of the image codec (image_codec.h) share: the PNG
// decoder (png_decode.cc), the JPEG decoder (jpeg_decode.cc), the PNG
// encoder (png_encode.cc) and the entry points that validate the options
// and tell the formats apart (image_codec.cc, with image_header.h).
// Internal to core/frame.
//
// How these files use setjmp/longjmp: libpng and libjpeg report errors by
// calling a function that must not return; ours longjmps back. Each setjmp
// lives in a small C-style function (PngReadHeader, PngReadPixels,
// PngWriteAll, JpegReadHeader, JpegReadPixels) that holds no object with a
// destructor and keeps everything it changes in a state struct owned by
// its C++ caller, so a jump skips only library frames and our callbacks.
// The C++ caller owns the pixel buffer and releases the library's structs
// in a guard's destructor on every path.

#include <png.h>

#include <bit>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/frame/image_codec.h"

namespace fovea::image_codec_internal {

// Longest library message kept; libjpeg's format_message writes up to
// JMSG_LENGTH_MAX bytes.
inline constexpr size_t kMessageChars = 256;
inline constexpr bool kLittleEndianHost =
    std::endian::native == std::endian::little;

// Where a library's error callback jumps to, and what the library said.
// Trivially destructible: it is live across longjmp.
struct LongJumpError {
  std::jmp_buf jump;
  char message[kMessageChars] = "";
};

void SetMessage(LongJumpError* error, const char* message);

absl::Status Undecodable(absl::string_view kind, size_t size,
                         absl::string_view library, const char* message,
                         absl::string_view field);

absl::Status CheckSize(uint64_t width, uint64_t height,
                       const ImageDecodeOptions& options,
                       absl::string_view kind, absl::string_view field);

// An uninitialised image, and row pointers into it for the libraries.
struct PixelBuffer {
  cv::Mat image;
  std::vector<unsigned char*> rows;
};

absl::StatusOr<PixelBuffer> AllocatePixels(uint32_t width, uint32_t height,
                                           int type);

// libpng's error callback (error pointer: a LongJumpError) and its warning
// callback, for reading and writing.
[[noreturn]] void OnPngError(png_structp png, png_const_charp message);
// Warnings (an odd iCCP profile, a bad ancillary CRC) change nothing in
// the pixels: ignored, not printed.
void OnPngWarning(png_structp, png_const_charp);

// The decoders of DecodeImage: `file` starts with the format's signature,
// `options` are valid; errors as DecodeImage documents them.
absl::StatusOr<cv::Mat> DecodePng(absl::string_view file,
                                  const ImageDecodeOptions& options,
                                  absl::string_view field);
absl::StatusOr<cv::Mat> DecodeJpeg(absl::string_view file,
                                   const ImageDecodeOptions& options,
                                   absl::string_view field);

}  // namespace fovea::image_codec_internal

#endif  // FOVEA_CORE_FRAME_IMAGE_CODEC_INTERNAL_H_
