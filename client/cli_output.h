#ifndef FOVEA_CLIENT_CLI_OUTPUT_H_
#define FOVEA_CLIENT_CLI_OUTPUT_H_

#include <opencv2/core.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/perception.pb.h"
#include "fovea/v1/segment.pb.h"
#include "google/protobuf/message.h"

namespace fovea::client {

// What fovea-client prints and writes. Part of the command-line client only.

// Protobuf JSON (proto3 mapping: lowerCamelCase names, fields at their
// default value included, 64-bit integers as strings, bytes as base64, NaN as
// "NaN"). One line without `pretty`.
std::string ToJson(const google::protobuf::Message& message,
                   bool pretty = false);

// The readable form of a Detect answer: a table of rank, u, v, x y z
// (metres), saliency; the support plane; per-stage timings; the round trip.
void PrintDetectTable(const fovea::v1::DetectResponse& response,
                      absl::Duration round_trip, std::ostream& out);

// One line for one stream message, prefixed with its latency since the call
// started.
std::string DescribeSegmentMessage(const fovea::v1::SegmentResponse& message,
                                   absl::Duration since_start);

void PrintCapabilities(const fovea::v1::GetCapabilitiesResponse& capabilities,
                       std::ostream& out);

// Writes into `dir` (created if missing): response.json; overlay.png, the
// colour image with the attention points as numbered circles (rank 0
// largest); saliency.png, the master map colour-mapped, when the response
// carries it; saliency_<name>.png per channel map; saliency_overlay.png, the
// master map blended over the colour image with the points. `color_bgr`
// may be empty (no overlays then). Returns the paths written.
absl::StatusOr<std::vector<std::string>> WriteDetectOutputs(
    const std::string& dir, const fovea::v1::DetectResponse& response,
    const cv::Mat& color_bgr);

// Writes mask_<index>.png (255 inside) of one object into `dir` (created
// if needed): called as each object arrives. Returns the path written.
absl::StatusOr<std::string> WriteObjectMask(
    const std::string& dir, const fovea::v1::ObjectResult& object);

// Writes into `dir`, once the stream has ended: responses.jsonl (one
// message per line) and overlay.png with every mask tinted, its box and
// index drawn, and the attention points of the first message (the masks
// themselves were written as they arrived, WriteObjectMask). Returns the
// paths written.
absl::StatusOr<std::vector<std::string>> WriteSegmentOutputs(
    const std::string& dir,
    const std::vector<fovea::v1::SegmentResponse>& messages,
    const cv::Mat& color_bgr);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_CLI_OUTPUT_H_
