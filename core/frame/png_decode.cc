// The PNG decoder of DecodeImage (image_codec.h), with libpng: header,
// the transformations that give the requested layout, the rows (with
// interrupt checks and a bound on how far the file is read), and the
// chunk structure checked without inflating anything.

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdint>
#include <cstring>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/frame/image_codec_internal.h"
#include "core/frame/image_header.h"

namespace fovea::image_codec_internal {
namespace {

// One-channel output for kGrey / kAnyDepth from a 3-channel BGR decode.
absl::StatusOr<cv::Mat> ToGrey(const cv::Mat& bgr) {
  try {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return grey;
  } catch (const std::exception&) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "out of memory for a ", bgr.cols, " x ", bgr.rows, " grey image"));
  }
}

struct PngReadState {
  LongJumpError error;
  png_structp png = nullptr;
  png_infop info = nullptr;
  const unsigned char* data = nullptr;  // the file; not owned
  size_t size = 0;
  size_t position = 0;
  // From the header (PngReadHeader).
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
  bool has_trns = false;
  // Once the last row is being read, the file may be read up to here and
  // no further: libpng inflates whatever compressed data follows the
  // declared rows (checking for the end of the zlib stream), which a
  // hostile file can make gigabytes. SIZE_MAX: no bound yet.
  size_t read_limit = SIZE_MAX;
};

// Releases libpng's read structs on every path out of DecodePng.
struct PngReadGuard {
  PngReadState* state;
  ~PngReadGuard() {
    if (state->png != nullptr) {
      png_destroy_read_struct(&state->png, &state->info, nullptr);
    }
  }
};

void ReadPngBytes(png_structp png, png_bytep out, size_t length) {
  auto* state = static_cast<PngReadState*>(png_get_io_ptr(png));
  if (length > state->size - state->position) {
    png_error(png, "file truncated");
  }
  if (state->position + length > state->read_limit) {
    png_error(png, "more compressed image data than the declared rows need");
  }
  std::memcpy(out, state->data + state->position, length);
  state->position += length;
}

// Creates the read structs and reads the chunks before the image data.
// setjmp frame: no C++ objects here.
bool PngReadHeader(PngReadState* state) {
  if (setjmp(state->error.jump)) return false;
  state->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state->error,
                                      OnPngError, OnPngWarning);
  if (state->png == nullptr) {
    SetMessage(&state->error, "cannot create a read struct");
    return false;
  }
  state->info = png_create_info_struct(state->png);
  if (state->info == nullptr) {
    SetMessage(&state->error, "cannot create an info struct");
    return false;
  }
  // The caller checks the size against its own limits, with a better
  // message than libpng's; libpng keeps only the spec's bound.
  png_set_user_limits(state->png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  // Only the pixels matter: ancillary chunks other than tRNS (text,
  // compressed text, profiles, ...) are skipped unread, never inflated,
  // whatever their number or size; and libpng's own bounds on what it
  // would keep.
  static constexpr png_byte kSkipped[] =
      "bKGD\0cHRM\0eXIf\0gAMA\0hIST\0iCCP\0iTXt\0oFFs\0pCAL\0pHYs\0"
      "sBIT\0sCAL\0sPLT\0sRGB\0tEXt\0tIME\0zTXt";
  png_set_keep_unknown_chunks(state->png, PNG_HANDLE_CHUNK_NEVER, nullptr, 0);
  png_set_keep_unknown_chunks(state->png, PNG_HANDLE_CHUNK_NEVER, kSkipped,
                              static_cast<int>(sizeof(kSkipped) / 5));
  png_set_chunk_cache_max(state->png, 32);
  png_set_chunk_malloc_max(state->png, 1 << 20);
  png_set_read_fn(state->png, state, ReadPngBytes);
  png_read_info(state->png, state->info);
  png_get_IHDR(state->png, state->info, &state->width, &state->height,
               &state->bit_depth, &state->color_type, nullptr, nullptr,
               nullptr);
  state->has_trns = png_get_valid(state->png, state->info, PNG_INFO_tRNS) != 0;
  return true;
}

// The libpng transformations that give a mode's layout, and that layout.
struct PngPlan {
  bool palette_to_rgb = false;
  bool expand_grey = false;  // 1, 2, 4 bits to 8
  bool strip_16 = false;     // keep the high byte
  bool strip_alpha = false;
  bool trns_to_alpha = false;
  bool grey_to_rgb = false;
  bool bgr = false;
  bool swap = false;  // big-endian 16-bit samples to host order
  int channels = 0;
  int bit_depth = 0;
};

PngPlan PlanPng(const PngReadState& header, ImageDecodeMode mode) {
  const bool palette = header.color_type == PNG_COLOR_TYPE_PALETTE;
  const bool colour = (header.color_type & PNG_COLOR_MASK_COLOR) != 0;
  const bool alpha = (header.color_type & PNG_COLOR_MASK_ALPHA) != 0;
  const bool keep_16 =
      header.bit_depth == 16 && (mode == ImageDecodeMode::kAnyDepth ||
                                 mode == ImageDecodeMode::kUnchanged);
  // As cv::imdecode: tRNS becomes alpha only for colour files.
  const bool keep_alpha = mode == ImageDecodeMode::kUnchanged &&
                          (alpha || (colour && header.has_trns));
  PngPlan plan;
  plan.palette_to_rgb = palette;
  plan.expand_grey = !colour && header.bit_depth < 8;
  plan.strip_16 = header.bit_depth == 16 && !keep_16;
  plan.bit_depth = keep_16 ? 16 : 8;
  plan.swap = keep_16 && kLittleEndianHost;
  plan.strip_alpha = !keep_alpha;
  plan.trns_to_alpha = keep_alpha && header.has_trns;
  plan.grey_to_rgb = !colour && (mode == ImageDecodeMode::kColor || keep_alpha);
  plan.channels = keep_alpha ? 4 : (colour || plan.grey_to_rgb ? 3 : 1);
  plan.bgr = plan.channels >= 3;
  return plan;
}

// Applies `plan`; the passes libpng will make over the rows (7 for an
// interlaced file, else 1). setjmp frame: no C++ objects here.
bool PngStartPixels(PngReadState* state, const PngPlan& plan, size_t row_bytes,
                    int* passes) {
  if (setjmp(state->error.jump)) return false;
  if (plan.palette_to_rgb) png_set_palette_to_rgb(state->png);
  if (plan.expand_grey) png_set_expand_gray_1_2_4_to_8(state->png);
  if (plan.strip_16) png_set_strip_16(state->png);
  if (plan.strip_alpha) png_set_strip_alpha(state->png);
  if (plan.trns_to_alpha) png_set_tRNS_to_alpha(state->png);
  if (plan.grey_to_rgb) png_set_gray_to_rgb(state->png);
  if (plan.bgr) png_set_bgr(state->png);
  if (plan.swap) png_set_swap(state->png);
  *passes = png_set_interlace_handling(state->png);
  png_read_update_info(state->png, state->info);
  if (png_get_channels(state->png, state->info) != plan.channels ||
      png_get_bit_depth(state->png, state->info) != plan.bit_depth ||
      png_get_rowbytes(state->png, state->info) != row_bytes) {
    SetMessage(&state->error, "unexpected layout after transformations");
    return false;
  }
  return true;
}

// Reads rows [begin, end) of the current pass. setjmp frame: no C++
// objects here.
bool PngReadRows(PngReadState* state, png_bytepp rows, png_uint_32 begin,
                 png_uint_32 end) {
  if (setjmp(state->error.jump)) return false;
  for (png_uint_32 y = begin; y < end; ++y) {
    png_read_row(state->png, rows[y], nullptr);
  }
  return true;
}

// Rows read between two interrupt checks.
constexpr png_uint_32 kPngRowsPerCheck = 64;

// The file's chunk structure, without inflating anything: every chunk lies
// inside the file and IEND comes. libpng stops reading after the last row
// of the declared image; this is what refuses a file cut short after it
// (png_read_end would check that too, but inflates whatever compressed
// data follows the declared rows first). Empty when sound.
std::string CheckPngChunks(absl::string_view file) {
  size_t at = kPngSignature.size();
  while (at + 12 <= file.size()) {
    const auto byte = [&](size_t i) {
      return static_cast<uint32_t>(static_cast<unsigned char>(file[at + i]));
    };
    const uint32_t length =
        byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3);
    if (length > 0x7fffffffu || length > file.size() - at - 12) {
      return absl::StrCat("chunk at byte ", at, " runs past the end");
    }
    if (file.substr(at + 4, 4) == "IEND") return "";
    at += 12 + size_t{length};
  }
  return "no IEND chunk (file truncated)";
}

}  // namespace

absl::StatusOr<cv::Mat> DecodePng(absl::string_view file,
                                  const ImageDecodeOptions& options,
                                  absl::string_view field) {
  PngReadState state;
  state.data = reinterpret_cast<const unsigned char*>(file.data());
  state.size = file.size();
  PngReadGuard guard{&state};
  if (!PngReadHeader(&state)) {
    return Undecodable("PNG", file.size(), "libpng", state.error.message,
                       field);
  }
  absl::Status status =
      CheckSize(state.width, state.height, options, "PNG", field);
  if (!status.ok()) return status;

  const PngPlan plan = PlanPng(state, options.mode);
  const int depth = plan.bit_depth == 16 ? CV_16U : CV_8U;
  FOVEA_ASSIGN_OR_RETURN(PixelBuffer buffer,
                         AllocatePixels(state.width, state.height,
                                        CV_MAKETYPE(depth, plan.channels)));
  const size_t row_bytes = buffer.image.cols * buffer.image.elemSize();
  if (const std::string bad = CheckPngChunks(file); !bad.empty()) {
    return Undecodable("PNG", file.size(), "structure", bad.c_str(), field);
  }
  int passes = 1;
  if (!PngStartPixels(&state, plan, row_bytes, &passes)) {
    return Undecodable("PNG", file.size(), "libpng", state.error.message,
                       field);
  }
  for (int pass = 0; pass < passes; ++pass) {
    for (png_uint_32 y = 0; y < state.height; y += kPngRowsPerCheck) {
      if (options.interrupt) {
        FOVEA_RETURN_IF_ERROR(options.interrupt());
      }
      png_uint_32 end = std::min(state.height, y + kPngRowsPerCheck);
      const bool last = pass + 1 == passes && end == state.height;
      if (last && end - y > 1) {
        // All but the last row first, unbounded.
        if (!PngReadRows(&state, buffer.rows.data(), y, end - 1)) {
          return Undecodable("PNG", file.size(), "libpng", state.error.message,
                             field);
        }
        y = end - 1;
      }
      if (last) {
        // The last row's data (deflate grows incompressible data by a few
        // bytes per 16 kB), the zlib trailer, chunk headers and CRCs, and
        // one read of libpng's 8 kB buffer.
        state.read_limit =
            state.position + 2 * (row_bytes + 1) + (size_t{64} << 10);
      }
      if (!PngReadRows(&state, buffer.rows.data(), y, end)) {
        return Undecodable("PNG", file.size(), "libpng", state.error.message,
                           field);
      }
    }
  }
  const bool one_channel = options.mode == ImageDecodeMode::kGrey ||
                           options.mode == ImageDecodeMode::kAnyDepth;
  if (one_channel && plan.channels == 3) return ToGrey(buffer.image);
  return std::move(buffer.image);
}

}  // namespace fovea::image_codec_internal
