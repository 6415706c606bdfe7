#ifndef FOVEA_SERVER_CONVERT_H_
#define FOVEA_SERVER_CONVERT_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "absl/status/statusor.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/segment.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/frame.pb.h"
#include "fovea/v1/segment.pb.h"

namespace fovea::server {

// Conversions between the wire contract (fovea.v1) and core/'s types. No
// gRPC here: every function is tested on its own. One file per idea:
// convert_frame.cc, convert_detect_options.cc, convert_detect_response.cc
// and convert_segment.cc (what they share: convert_internal.h).

// Frames (convert_frame.cc).

// The wire frame as core's RawFrame. Non-owning: the views point into
// `frame`'s strings, which must outlive the result. Nothing is checked
// here; DecodeFrame validates and names the wire fields.
RawFrame ToRawFrame(const v1::Frame& frame);

// How ToProtoFrame writes depth.
enum class DepthEncoding {
  k32FC1,  // float32 metres, NaN for no data
  k16UC1,  // uint16 in units of `depth_scale` metres, 0 for no data
};

// A depth in metres as a 16-bit depth value in units of `metres_per_unit`
// (> 0): rounded to the nearest unit; NaN, 0, negative or beyond 16 bits
// is 0, no data.
uint16_t ToDepthUnits(float metres, double metres_per_unit);

// A decoded frame as raw wire images: colour "rgb8" (step = width * 3),
// depth as `depth_encoding` (step = width * bytes per pixel). For 16UC1,
// depth is rounded to units of `depth_scale` (metres per unit, > 0);
// values that do not fit in 16 bits, and NaN, become 0 (no data). The
// inverse of DecodeFrame for raw frames, used by the warm-up and tests.
v1::Frame ToProtoFrame(const RgbdFrame& frame, DepthEncoding depth_encoding,
                       double depth_scale = kDefaultDepthScale);

// Detect options (convert_detect_options.cc).

// Request options to core options, starting from core's defaults:
//   - empty `saliency` means the default channels; a weight of 0 means 1;
//     a negative or non-finite weight, or a channel without an operator,
//     is INVALID_ARGUMENT naming "options.saliency[i]...";
//   - an UNSPECIFIED enum means core's default; a value outside the enum
//     (proto3 enums are open) is INVALID_ARGUMENT naming the field;
//   - max_points 0 means core's default (one per region, at most 100);
//     above core's kMaxAttentionPoints is
//     INVALID_ARGUMENT naming "options.max_points";
//   - target_color_rgb must be empty or 3 values of at most 255, and
//     location_prior_sigma_px finite and >= 0 (INVALID_ARGUMENT);
//   - scene: the sensor (UNSPECIFIED = generic), processing_width (0 = 640),
//     gravity, support_plane and workspace when set, validated by core
//     (INVALID_ARGUMENT naming "options.scene.gravity", ...: NaN, zero or
//     non-unit vectors, empty boxes, depths out of order);
//   - finally core's Validate(DetectOptions): an operator or strategy not
//     built yet is UNIMPLEMENTED and names it, e.g. "options.saliency:
//     'sym3d' is not implemented yet".
absl::StatusOr<DetectOptions> ToDetectOptions(const v1::DetectOptions& options);

// Core options as the wire states them (for Capabilities' defaults).
v1::DetectOptions ToProtoDetectOptions(const DetectOptions& options);

// Enum values on the wire. Every core value has one.
v1::SaliencyOperator ToProtoEnum(SaliencyOp op);
v1::Pyramid ToProtoEnum(PyramidKind pyramid);
v1::LevelCombination ToProtoEnum(LevelCombination combination);
v1::Normalization ToProtoEnum(NormalizationKind normalization);
v1::Fusion ToProtoEnum(FusionKind fusion);
v1::SensorModel ToProtoEnum(SensorKind sensor);
v1::Extraction ToProtoEnum(ExtractionKind extraction);

// Detect responses (convert_detect_response.cc).

// A saliency map (CV_32FC1, values in [0, 1]) as a 16-bit grey PNG file:
// pixel = round(value * 65535), clamped to [0, 65535], NaN as 0. INTERNAL
// for a map of another type or when encoding fails.
absl::StatusOr<std::string> EncodeSaliencyPng(const cv::Mat& map);

// The response to `request` from core's result: request_id, frame_id and
// stamp echoed; points in order with rank 0, 1, ...; the support plane;
// the stage timings in order; the master map ("master") when
// options.return_saliency_map and each channel map (by its name) when
// options.return_channel_maps, as 16-bit PNG. Errors: INTERNAL when a map
// cannot be encoded.
absl::StatusOr<v1::DetectResponse> ToDetectResponse(
    const DetectResult& result, const v1::DetectRequest& request);

// The support plane as the wire states it: plane, inlier count, how many
// candidates there were and the chosen one's score.
v1::SupportPlane ToProtoSupportPlane(const SupportPlane& plane);

// Segmentation (convert_segment.cc).

// Segment's options from the request: method (UNSPECIFIED = COS), seeds
// as given (checked against the frame by core), detect_options as
// ToDetectOptions, max_objects (0 = no limit). Errors: INVALID_ARGUMENT
// naming the field (detect_options.*, seeds: more than kMaxAttentionPoints
// or a coordinate beyond any frame, method: unknown value).
absl::StatusOr<SegmentOptions> ToSegmentOptions(
    const v1::SegmentRequest& request);

// SegmentIncremental's options: attention_points as given (checked against
// the frame by core), detect_options as ToDetectOptions, max_objects (0 =
// no limit), time_budget_seconds (0 = none; negative or not finite is
// INVALID_ARGUMENT naming it).
absl::StatusOr<IncrementalOptions> ToIncrementalOptions(
    const v1::SegmentIncrementalRequest& request);

// The segmentation method on the wire. Every core value has one.
v1::SegmentationMethod ToProtoEnum(SegmentMethod method);

// COCO RLE (segment.proto RleMask) of a CV_8UC1 mask, non-zero = inside.
v1::RleMask ToRleMask(const cv::Mat& mask);

// The first message of a segmentation stream: the seeds used, ranked in
// order, and the support plane (when not null).
v1::SegmentResponse ToPointsMessage(const std::vector<AttentionPoint>& points,
                                    const std::string& request_id,
                                    const SupportPlane* plane = nullptr);

// One object's message.
v1::SegmentResponse ToObjectMessage(const SegmentedObject& object,
                                    const std::string& request_id);

// The last message: `last` set and the summary, with `stop_reason`.
v1::SegmentResponse ToSummaryMessage(const SegmentSummary& summary,
                                     v1::StopReason stop_reason,
                                     const std::string& request_id);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_CONVERT_H_
