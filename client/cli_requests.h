#ifndef FOVEA_CLIENT_CLI_REQUESTS_H_
#define FOVEA_CLIENT_CLI_REQUESTS_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cli_frame.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/segment.pb.h"

namespace fovea::client {

// What fovea-client's request flags ask for. The flags are defined in
// cli_requests.cc: the frame (--color, --depth, --pcd, --synthetic, --fx,
// --fy, --cx, --cy, --depth_scale, --frame_id), --request_id, the detect
// options (--saliency, --extract, --pyramid, --norm, --combine, --fusion,
// --maps, --target_color, --location_prior, --location_sigma,
// --split_edges, --points), the scene (--sensor, --processing_width,
// --gravity, --support_plane, --workspace_box, --min_depth, --max_depth)
// and the segmentation (--method, --max_objects, --seeds,
// --time_budget_ms). Part of the command-line client only; main.cc keeps
// the connection and output flags and runs the commands.

// The frame the frame flags name; LoadFrame's errors (cli_frame.h).
absl::StatusOr<LoadedFrame> FrameFromFlags();

// --request_id, or "cli-<Unix time in microseconds>" when it is empty.
std::string RequestId();

// Detect options from the flags, the scene's included; an empty flag
// leaves its field unset (the server's default). `return_saliency_map`
// asks for the master map (fovea-client sets it for --out).
// INVALID_ARGUMENT naming a bad flag; the server validates the values.
absl::StatusOr<fovea::v1::DetectOptions> DetectOptionsFromFlags(
    bool return_saliency_map);

// segment's and segment-incremental's own flags.
struct SegmentParameters {
  // --method; UNSPECIFIED (the server's default) when not given.
  fovea::v1::SegmentationMethod method =
      fovea::v1::SEGMENTATION_METHOD_UNSPECIFIED;
  int32_t max_objects = 0;      // --max_objects, >= 0; 0 = no limit
  double time_budget_ms = 0.0;  // --time_budget_ms, >= 0; 0 = none
  // --seeds: pixels (u, v) = (column, row), in the order given.
  std::vector<std::pair<uint32_t, uint32_t>> seeds;
  // --object_points (xyz | indices) and --max_points: each object's points.
  fovea::v1::ObjectPointsOptions object_points;
};

// The segmentation flags; INVALID_ARGUMENT naming a bad one (an unknown
// --method, a negative --max_objects or --time_budget_ms, a --seeds item
// that is not 'u,v').
absl::StatusOr<SegmentParameters> SegmentParametersFromFlags();

// track: the frames of --frames (<n>_color.png and <n>_depth.png, in the
// order of <n>, with the intrinsics and depth scale flags);
// INVALID_ARGUMENT naming --frames when it is empty, has none, or a colour
// file lacks its depth.
absl::StatusOr<std::vector<FrameSource>> TrackFramesFromFlags();
double TrackFpsFromFlags();  // --fps

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_CLI_REQUESTS_H_
