#ifndef FOVEA_CORE_FRAME_FRAME_DECODE_H_
#define FOVEA_CORE_FRAME_FRAME_DECODE_H_

#include <cstdint>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// One image as it arrives on the wire, shaped like ROS sensor_msgs/Image.
// Non-owning: the views must outlive the call that reads them.
//   Raw form: `data` holds height rows of `step` bytes; `encoding` is
//     "rgb8"/"bgr8" (colour) or "16UC1"/"32FC1" (depth), little-endian.
//   Compressed form: `compressed` holds a PNG (colour or 16-bit depth) or a
//     JPEG (colour) file; width/height/step/encoding may then be 0/empty,
//     and when set must agree with the file.
struct RawImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::string_view encoding;
  bool is_bigendian = false;
  uint32_t step = 0;
  std::string_view data;
  std::string_view compressed;
};

// Metres per unit of 16-bit depth when a frame's depth_scale is 0.
inline constexpr double kDefaultDepthScale = 0.001;

struct RawFrame {
  RawImage color;
  RawImage depth;
  Intrinsics intrinsics;
  double depth_scale = 0.0;  // metres per 16-bit depth unit; 0 means 0.001
};

// Depths beyond this are no data: no RGB-D sensor measures that far, and
// unbounded coordinates would make every metric grid unbounded, metres.
inline constexpr float kMaxDepthMetres = 100.0f;
// Plausible pinhole focal lengths, pixels. 10 px on a 640-px image is a
// 176-degree field of view, wider than any pinhole depth camera; 1e6 px is
// a 0.04-degree telescope.
inline constexpr double kMinFocalPixels = 10.0;
inline constexpr double kMaxFocalPixels = 1e6;

struct FrameLimits {
  uint32_t max_width = 1920;   // pixels; larger frames are refused
  uint32_t max_height = 1080;  // pixels; larger frames are refused
};

absl::Status Validate(const FrameLimits& limits);

// Validates and decodes a frame. Every size is checked against `limits`
// before any pixel buffer is allocated (for compressed images, from the
// PNG/JPEG header). Errors are INVALID_ARGUMENT and name the field with
// the wire's names, e.g. "frame.color.step: 1000 is less than width * 3 =
// 1920". Refused: size or step mismatch, unknown or big-endian encoding,
// colour and depth of different sizes, zero/negative/non-finite
// intrinsics, non-finite or non-positive depth_scale, a frame above the
// limits, no valid depth pixel, undecodable PNG/JPEG.
// On success the depth is in metres with NaN for no data (0, NaN,
// negative values and values beyond kMaxDepthMetres all become NaN).
// fx and fy must lie in [kMinFocalPixels, kMaxFocalPixels]; cx and cy may
// lie outside the image (a crop can put the principal point there) but
// within 10 focal lengths of the image's centre.
// `interrupt` is checked while compressed images decode (ImageDecodeOptions)
// and its error returned as is.
absl::StatusOr<RgbdFrame> DecodeFrame(const RawFrame& raw,
                                      const FrameLimits& limits,
                                      const InterruptCheck& interrupt = {});

// Checks intrinsics alone; `field` prefixes the message ("frame.intrinsics").
absl::Status ValidateIntrinsics(const Intrinsics& intrinsics,
                                std::string_view field);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_FRAME_DECODE_H_
