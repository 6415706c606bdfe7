// The entry points of the image codec: options, the dispatch on the file's
// signature, and the pieces the decoders and the encoder share
// (image_codec_internal.h).

#include "core/frame/image_codec.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <exception>

#include "absl/strings/str_cat.h"
#include "core/base/strings.h"
#include "core/frame/image_codec_internal.h"
#include "core/frame/image_header.h"

namespace fovea {
namespace image_codec_internal {

void SetMessage(LongJumpError* error, const char* message) {
  std::snprintf(error->message, sizeof(error->message), "%s", message);
}

absl::Status Undecodable(absl::string_view kind, size_t size,
                         absl::string_view library, const char* message,
                         absl::string_view field) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": not a decodable ",
                                                 kind, " (", size, " bytes; ",
                                                 library, ": ", message, ")"));
}

absl::Status CheckSize(uint64_t width, uint64_t height,
                       const ImageDecodeOptions& options,
                       absl::string_view kind, absl::string_view field) {
  if (width > options.max_width) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": the ", kind, " header's width ", width,
                     " exceeds the limit of ", options.max_width, " pixels"));
  }
  if (height > options.max_height) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": the ", kind, " header's height ", height,
                     " exceeds the limit of ", options.max_height, " pixels"));
  }
  return absl::OkStatus();
}

absl::StatusOr<PixelBuffer> AllocatePixels(uint32_t width, uint32_t height,
                                           int type) {
  try {
    PixelBuffer buffer;
    buffer.image.create(static_cast<int>(height), static_cast<int>(width),
                        type);
    buffer.rows.resize(height);
    for (uint32_t v = 0; v < height; ++v) {
      buffer.rows[v] = buffer.image.ptr<unsigned char>(static_cast<int>(v));
    }
    return buffer;
  } catch (const std::exception&) {  // std::bad_alloc or cv::Exception
    return absl::ResourceExhaustedError(
        absl::StrCat("out of memory for a ", width, " x ", height, " image"));
  }
}

[[noreturn]] void OnPngError(png_structp png, png_const_charp message) {
  auto* error = static_cast<LongJumpError*>(png_get_error_ptr(png));
  SetMessage(error, message);
  std::longjmp(error->jump, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

}  // namespace image_codec_internal

absl::Status Validate(const ImageDecodeOptions& options) {
  if (options.max_width == 0 || options.max_width > kLargestDecodeSide) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.max_width: ", options.max_width,
                     " is not in [1, ", kLargestDecodeSide, "]"));
  }
  if (options.max_height == 0 || options.max_height > kLargestDecodeSide) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.max_height: ", options.max_height,
                     " is not in [1, ", kLargestDecodeSide, "]"));
  }
  switch (options.mode) {
    case ImageDecodeMode::kColor:
    case ImageDecodeMode::kGrey:
    case ImageDecodeMode::kAnyDepth:
    case ImageDecodeMode::kUnchanged:
      return absl::OkStatus();
  }
  return absl::InvalidArgumentError(
      absl::StrCat("options.mode: ", static_cast<int>(options.mode),
                   " is not an ImageDecodeMode"));
}

absl::StatusOr<cv::Mat> DecodeImage(std::string_view file,
                                    const ImageDecodeOptions& options,
                                    std::string_view field_name) {
  absl::Status status = Validate(options);
  if (!status.ok()) return status;
  const absl::string_view bytes = AbslView(file);
  const absl::string_view field = AbslView(field_name);
  if (IsPngFile(file)) {
    return image_codec_internal::DecodePng(bytes, options, field);
  }
  if (IsJpegFile(file)) {
    return image_codec_internal::DecodeJpeg(bytes, options, field);
  }
  return absl::InvalidArgumentError(absl::StrCat(
      field, ": neither a PNG nor a JPEG (", bytes.size(), " bytes)"));
}

}  // namespace fovea
