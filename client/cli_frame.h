#ifndef FOVEA_CLIENT_CLI_FRAME_H_
#define FOVEA_CLIENT_CLI_FRAME_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "fovea/v1/frame.pb.h"

namespace fovea::client {

// Where fovea-client takes its frame from: exactly one of a colour + depth
// file pair, an OSD PCD, or a synthetic scene. Part of the command-line
// client only (it uses core/ and OpenCV; the client library does not).
struct FrameSource {
  std::string color_path;  // PNG or JPEG, sent as is
  std::string depth_path;  // 16-bit grey PNG in `depth_scale` units, sent as is
  std::string pcd_path;    // OSD PCD, sent raw as rgb8 + 32FC1
  std::optional<uint64_t> synthetic_seed;  // core/synth scene, sent raw
  // Intrinsics, pixels. Unset ones default to the OSD Kinect v1 values
  // (fx = fy = 525, cx = 319.5, cy = 239.5); a synthetic scene defaults to
  // the intrinsics it was rendered with.
  std::optional<double> fx, fy, cx, cy;
  double depth_scale = 0.001;  // metres per depth unit of a 16-bit PNG
  std::string frame_id;        // echoed back by the server
};

struct LoadedFrame {
  fovea::v1::Frame frame;   // ready to send
  cv::Mat color_bgr;        // CV_8UC3 BGR, for overlays; empty if undecodable
  std::string description;  // one line for humans, e.g. "synthetic scene 1"
};

// Builds the frame. INVALID_ARGUMENT when the source is ambiguous or
// incomplete (naming the flags), NOT_FOUND for a missing file, and the
// loaders' errors otherwise.
absl::StatusOr<LoadedFrame> LoadFrame(const FrameSource& source);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_CLI_FRAME_H_
