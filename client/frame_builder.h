#ifndef FOVEA_CLIENT_FRAME_BUILDER_H_
#define FOVEA_CLIENT_FRAME_BUILDER_H_

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "fovea/v1/frame.pb.h"

namespace fovea::client {

// Builds the wire form of an RGB-D frame (fovea.v1.Frame, frame.proto) from
// raw pixel buffers or from PNG/JPEG file bytes. No OpenCV: a buffer is a
// pointer, a size and an encoding. Nothing here talks to a server; the server
// has the last word on what it accepts (GetCapabilities).

// Raw encodings of frame.proto and their bytes per pixel:
//   "rgb8", "bgr8" -> 3, "16UC1" -> 2, "32FC1" -> 4.
// Returns 0 for any other string (encodings are case-sensitive, as in ROS).
int BytesPerPixel(absl::string_view encoding);

// A raw image from `size_bytes` bytes at `data`: `height` rows of `step`
// bytes each, the first `width * BytesPerPixel(encoding)` of every row being
// pixels, little-endian. `step` 0 means tightly packed. The last row may be
// short (only its pixels need be present), so a view into a larger buffer
// works. The result is always tightly packed: step = width * bytes per pixel,
// data of step * height bytes, is_bigendian false.
// Errors (INVALID_ARGUMENT, naming the field): unknown encoding, zero width
// or height, step smaller than a row of pixels, size_bytes too small, null
// data.
absl::StatusOr<fovea::v1::Image> MakeRawImage(const void* data,
                                              size_t size_bytes, uint32_t width,
                                              uint32_t height,
                                              absl::string_view encoding,
                                              size_t step = 0);

// What the header of a PNG or JPEG file says.
struct CompressedInfo {
  std::string format;  // "png" or "jpeg"
  uint32_t width = 0;  // pixels
  uint32_t height = 0;
  int channels = 0;   // 1 grey, 2 grey + alpha, 3 colour, 4 colour + alpha
  int bit_depth = 0;  // bits per channel sample: 8 or 16 (PNG), 8 (JPEG)
};

// Reads the size and pixel layout from a PNG's IHDR chunk or a JPEG's SOF
// marker, without decoding pixels. INVALID_ARGUMENT for bytes that are
// neither, or a truncated header.
absl::StatusOr<CompressedInfo> ProbeCompressedImage(absl::string_view bytes);

// A compressed image holding the whole file `bytes` as they are (no
// re-encoding). width and height are filled from the file's header (the
// proto requires them to agree with the file when set); encoding and step
// stay empty / 0. Errors as ProbeCompressedImage.
absl::StatusOr<fovea::v1::Image> MakeCompressedImage(std::string bytes);

// Reads a file into a string. NOT_FOUND when it cannot be opened.
absl::StatusOr<std::string> ReadFileBytes(const std::string& path);

// Pinhole intrinsics in pixels (frame.proto: fx, fy > 0, cx, cy finite;
// checked by the server, not here).
fovea::v1::Intrinsics MakeIntrinsics(double fx, double fy, double cx,
                                     double cy);

// A frame from a colour and a depth image. `depth_scale` is metres per unit
// of 16UC1 / 16-bit PNG depth (0 = the server's default, 0.001).
fovea::v1::Frame MakeFrame(fovea::v1::Image color, fovea::v1::Image depth,
                           const fovea::v1::Intrinsics& intrinsics,
                           double depth_scale = 0.001);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_FRAME_BUILDER_H_
