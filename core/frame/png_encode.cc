// EncodePng (image_codec.h), with libpng: cv::imencode's defaults, output
// into a growing C buffer.

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/frame/image_codec.h"
#include "core/frame/image_codec_internal.h"

namespace fovea {
namespace {

using image_codec_internal::kLittleEndianHost;
using image_codec_internal::LongJumpError;
using image_codec_internal::OnPngError;
using image_codec_internal::OnPngWarning;
using image_codec_internal::SetMessage;

// PNG writing (cv::imencode's defaults): filter and zlib strategy.
constexpr int kPngWriteFilter = PNG_FILTER_SUB;
constexpr int kPngWriteStrategy = Z_RLE;

struct PngWriteState {
  LongJumpError error;
  png_structp png = nullptr;
  png_infop info = nullptr;
  unsigned char* bytes = nullptr;  // std::malloc'ed; freed by PngWriteGuard
  size_t size = 0;
  size_t capacity = 0;
};

struct PngWriteGuard {
  PngWriteState* state;
  ~PngWriteGuard() {
    if (state->png != nullptr) {
      png_destroy_write_struct(&state->png, &state->info);
    }
    std::free(state->bytes);
  }
};

// Appends to a C buffer: a std::string could throw through libpng.
void WritePngBytes(png_structp png, png_bytep data, size_t length) {
  auto* state = static_cast<PngWriteState*>(png_get_io_ptr(png));
  if (length > state->capacity - state->size) {
    const size_t capacity = std::max(2 * state->capacity, state->size + length);
    void* grown = std::realloc(state->bytes, capacity);
    if (grown == nullptr) png_error(png, "out of memory");
    state->bytes = static_cast<unsigned char*>(grown);
    state->capacity = capacity;
  }
  std::memcpy(state->bytes + state->size, data, length);
  state->size += length;
}

void FlushPng(png_structp) {}

struct PngWriteLayout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 8;
  int color_type = PNG_COLOR_TYPE_GRAY;
  bool bgr = false;   // rows hold B, G, R
  bool swap = false;  // rows hold little-endian 16-bit samples
  int compression_level = 1;
};

// setjmp frame: no C++ objects here.
bool PngWriteAll(PngWriteState* state, const PngWriteLayout& layout,
                 png_bytepp rows) {
  if (setjmp(state->error.jump)) return false;
  state->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state->error,
                                       OnPngError, OnPngWarning);
  if (state->png == nullptr) {
    SetMessage(&state->error, "cannot create a write struct");
    return false;
  }
  state->info = png_create_info_struct(state->png);
  if (state->info == nullptr) {
    SetMessage(&state->error, "cannot create an info struct");
    return false;
  }
  png_set_write_fn(state->png, state, WritePngBytes, FlushPng);
  png_set_filter(state->png, PNG_FILTER_TYPE_BASE, kPngWriteFilter);
  png_set_compression_level(state->png, layout.compression_level);
  png_set_compression_strategy(state->png, kPngWriteStrategy);
  png_set_IHDR(state->png, state->info, layout.width, layout.height,
               layout.bit_depth, layout.color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(state->png, state->info);
  if (layout.bgr) png_set_bgr(state->png);
  if (layout.swap) png_set_swap(state->png);
  png_write_image(state->png, rows);
  png_write_end(state->png, nullptr);
  return true;
}

}  // namespace

absl::Status Validate(const PngEncodeOptions& options) {
  if (options.compression_level < 0 || options.compression_level > 9) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.compression_level: ", options.compression_level,
                     " is not in [0, 9]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> EncodePng(const cv::Mat& image,
                                      const PngEncodeOptions& options) {
  absl::Status status = Validate(options);
  if (!status.ok()) return status;
  PngWriteLayout layout;
  switch (image.type()) {
    case CV_8UC1:
      break;
    case CV_8UC3:
      layout.color_type = PNG_COLOR_TYPE_RGB;
      layout.bgr = true;
      break;
    case CV_16UC1:
      layout.bit_depth = 16;
      layout.swap = kLittleEndianHost;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("image: type ", image.type(),
                       " is not CV_8UC1, CV_8UC3 or CV_16UC1"));
  }
  if (image.empty() || image.dims != 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("image: ", image.cols, " x ", image.rows,
                     " is not a non-empty 2-D image"));
  }
  layout.width = static_cast<png_uint_32>(image.cols);
  layout.height = static_cast<png_uint_32>(image.rows);
  layout.compression_level = options.compression_level;

  PngWriteState state;
  PngWriteGuard guard{&state};
  // libpng copies each row before transforming it, so the const image is
  // only read.
  std::vector<png_bytep> rows(image.rows);
  for (int v = 0; v < image.rows; ++v) {
    rows[v] = const_cast<png_bytep>(image.ptr<unsigned char>(v));
  }
  if (!PngWriteAll(&state, layout, rows.data())) {
    return absl::InternalError(
        absl::StrCat("EncodePng: libpng: ", state.error.message));
  }
  return std::string(reinterpret_cast<const char*>(state.bytes), state.size);
}

}  // namespace fovea
