#include "core/frame/image_codec.h"

// jpeglib.h needs FILE and size_t declared first.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
#include <jerror.h>
// clang-format on
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <csetjmp>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/guarded.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"

// How this file uses setjmp/longjmp: libpng and libjpeg report errors by
// calling a function that must not return; ours longjmps back. Each setjmp
// lives in a small C-style function (PngReadHeader, PngReadPixels,
// PngWriteAll, JpegReadHeader, JpegReadPixels) that holds no object with a
// destructor and keeps everything it changes in a state struct owned by
// its C++ caller, so a jump skips only library frames and our callbacks.
// The C++ caller owns the pixel buffer and releases the library's structs
// in a guard's destructor on every path.

namespace fovea {
namespace {

constexpr absl::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
// Longest library message kept; libjpeg's format_message writes up to
// JMSG_LENGTH_MAX bytes.
constexpr size_t kMessageChars = 256;
static_assert(kMessageChars >= JMSG_LENGTH_MAX);
// Progressive JPEG scans decoded before giving up: a real file has about
// ten; thousands of tiny scans are a way to burn CPU. 500 is
// libjpeg-turbo's own TJFLAG_LIMITSCANS bound.
constexpr int kMaxJpegScans = 500;
// PNG writing (cv::imencode's defaults): filter and zlib strategy.
constexpr int kPngWriteFilter = PNG_FILTER_SUB;
constexpr int kPngWriteStrategy = Z_RLE;
constexpr bool kLittleEndianHost = std::endian::native == std::endian::little;

// Where a library's error callback jumps to, and what the library said.
// Trivially destructible: it is live across longjmp.
struct LongJumpError {
  std::jmp_buf jump;
  char message[kMessageChars] = "";
};

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

// An uninitialised image, and row pointers into it for the libraries.
struct PixelBuffer {
  cv::Mat image;
  std::vector<unsigned char*> rows;
};

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

// ------------------------------------------------------------------ libpng

[[noreturn]] void OnPngError(png_structp png, png_const_charp message) {
  auto* error = static_cast<LongJumpError*>(png_get_error_ptr(png));
  SetMessage(error, message);
  std::longjmp(error->jump, 1);
}

// Warnings (an odd iCCP profile, a bad ancillary CRC) change nothing in
// the pixels: ignored, not printed.
void OnPngWarning(png_structp, png_const_charp) {}

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

// ------------------------------------------------------------- libjpeg-turbo

struct JpegErrorManager {
  jpeg_error_mgr manager;  // first: libjpeg hands back a pointer to it
  LongJumpError error;
};

LongJumpError* JpegError(j_common_ptr cinfo) {
  return &reinterpret_cast<JpegErrorManager*>(cinfo->err)->error;
}

[[noreturn]] void OnJpegError(j_common_ptr cinfo) {
  LongJumpError* error = JpegError(cinfo);
  (*cinfo->err->format_message)(cinfo, error->message);
  std::longjmp(error->jump, 1);
}

// Trace messages (level >= 0) are dropped. A warning (level -1) means the
// data is corrupt or cut short (libjpeg would fill the rest with grey), so
// it ends the decode, except for the few about metadata that the pixels
// do not depend on.
void OnJpegMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;
  const int code = cinfo->err->msg_code;
  if (code == JWRN_JFIF_MAJOR || code == JWRN_ADOBE_XFORM ||
      code == JWRN_BOGUS_ICC) {
    return;
  }
  OnJpegError(cinfo);
}

void OnJpegProgress(j_common_ptr cinfo) {
  if (!cinfo->is_decompressor) return;
  const int scan = reinterpret_cast<j_decompress_ptr>(cinfo)->input_scan_number;
  if (scan <= kMaxJpegScans) return;
  LongJumpError* error = JpegError(cinfo);
  std::snprintf(error->message, sizeof(error->message),
                "more than %d progressive scans", kMaxJpegScans);
  std::longjmp(error->jump, 1);
}

// Value-initialised, so jpeg_destroy_decompress is safe on it even if
// jpeg_create_decompress never ran.
struct JpegReadState {
  jpeg_decompress_struct cinfo;
  JpegErrorManager errors;
  jpeg_progress_mgr progress;
};

// Releases libjpeg's memory on every path out of DecodeJpeg.
struct JpegReadGuard {
  JpegReadState* state;
  ~JpegReadGuard() { jpeg_destroy_decompress(&state->cinfo); }
};

// Creates the decompressor and reads the markers up to the first scan.
// setjmp frame: no C++ objects here.
bool JpegReadHeader(JpegReadState* state, const unsigned char* data,
                    size_t size) {
  if (setjmp(state->errors.error.jump)) return false;
  state->cinfo.err = jpeg_std_error(&state->errors.manager);
  state->errors.manager.error_exit = OnJpegError;
  state->errors.manager.emit_message = OnJpegMessage;
  jpeg_create_decompress(&state->cinfo);
  state->progress.progress_monitor = OnJpegProgress;
  state->cinfo.progress = &state->progress;
  jpeg_mem_src(&state->cinfo, data, size);
  if (jpeg_read_header(&state->cinfo, TRUE) != JPEG_HEADER_OK) {
    SetMessage(&state->errors.error, "tables only, no image");
    return false;
  }
  return true;
}

// Decodes every scanline into `rows`, then reads to the end of the file.
// setjmp frame: no C++ objects here.
bool JpegReadPixels(JpegReadState* state, JSAMPARRAY rows, int channels) {
  if (setjmp(state->errors.error.jump)) return false;
  j_decompress_ptr cinfo = &state->cinfo;
  jpeg_start_decompress(cinfo);
  if (cinfo->output_width != cinfo->image_width ||
      cinfo->output_height != cinfo->image_height ||
      cinfo->output_components != channels) {
    SetMessage(&state->errors.error, "unexpected output layout");
    return false;
  }
  while (cinfo->output_scanline < cinfo->output_height) {
    if (jpeg_read_scanlines(cinfo, rows + cinfo->output_scanline, 1) != 1) {
      SetMessage(&state->errors.error, "no scanline read");
      return false;
    }
  }
  jpeg_finish_decompress(cinfo);
  return true;
}

absl::StatusOr<cv::Mat> DecodeJpeg(absl::string_view file,
                                   const ImageDecodeOptions& options,
                                   absl::string_view field) {
  JpegReadState state{};
  JpegReadGuard guard{&state};
  if (!JpegReadHeader(&state,
                      reinterpret_cast<const unsigned char*>(file.data()),
                      file.size())) {
    return Undecodable("JPEG", file.size(), "libjpeg",
                       state.errors.error.message, field);
  }
  jpeg_decompress_struct& cinfo = state.cinfo;
  if (cinfo.jpeg_color_space != JCS_GRAYSCALE &&
      cinfo.jpeg_color_space != JCS_YCbCr &&
      cinfo.jpeg_color_space != JCS_RGB) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ": a JPEG in colour space ", cinfo.jpeg_color_space, " with ",
        cinfo.num_components,
        " components; only grey, YCbCr and RGB JPEGs are taken (no CMYK)"));
  }
  absl::Status status =
      CheckSize(cinfo.image_width, cinfo.image_height, options, "JPEG", field);
  if (!status.ok()) return status;

  const bool grey = options.mode == ImageDecodeMode::kGrey ||
                    options.mode == ImageDecodeMode::kAnyDepth ||
                    (options.mode == ImageDecodeMode::kUnchanged &&
                     cinfo.num_components == 1);
  cinfo.out_color_space = grey ? JCS_GRAYSCALE : JCS_EXT_BGR;
  const int channels = grey ? 1 : 3;
  FOVEA_ASSIGN_OR_RETURN(PixelBuffer buffer,
                         AllocatePixels(cinfo.image_width, cinfo.image_height,
                                        CV_MAKETYPE(CV_8U, channels)));
  if (!JpegReadPixels(&state, buffer.rows.data(), channels)) {
    return Undecodable("JPEG", file.size(), "libjpeg",
                       state.errors.error.message, field);
  }
  return std::move(buffer.image);
}

// --------------------------------------------------------------- PNG write

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
  if (bytes.substr(0, kPngSignature.size()) == kPngSignature) {
    return DecodePng(bytes, options, field);
  }
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
      static_cast<unsigned char>(bytes[1]) == 0xD8) {
    return DecodeJpeg(bytes, options, field);
  }
  return absl::InvalidArgumentError(absl::StrCat(
      field, ": neither a PNG nor a JPEG (", bytes.size(), " bytes)"));
}

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
  return Guarded("EncodePng", [&]() -> absl::StatusOr<std::string> {
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
  });
}

}  // namespace fovea
