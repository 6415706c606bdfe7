// The JPEG decoder of DecodeImage (image_codec.h), with libjpeg-turbo:
// grey, YCbCr and RGB files; a warning about the data ends the decode, and
// progressive files are bounded in scans.

// jpeglib.h needs FILE and size_t declared first.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
#include <jerror.h>
// clang-format on

#include <csetjmp>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/frame/image_codec_internal.h"

namespace fovea::image_codec_internal {
namespace {

// A LongJumpError's message holds all that format_message writes.
static_assert(kMessageChars >= JMSG_LENGTH_MAX);

// Progressive JPEG scans decoded before giving up: a real file has about
// ten; thousands of tiny scans are a way to burn CPU. 500 is
// libjpeg-turbo's own TJFLAG_LIMITSCANS bound.
constexpr int kMaxJpegScans = 500;

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

}  // namespace

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

}  // namespace fovea::image_codec_internal
