#ifndef FOVEA_SERVER_HANDLE_DETECT_H_
#define FOVEA_SERVER_HANDLE_DETECT_H_

#include "absl/status/statusor.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/detect.h"
#include "fovea/v1/detect.pb.h"

namespace fovea::server {

// The Detect work of one call, without gRPC: decode the wire frame
// (DecodeFrame, checked against `limits`), check `interrupt`, run core's
// RunDetect (which checks `interrupt` between its stages) and convert the
// result. `options` are the request's, already converted and validated
// (ToDetectOptions). Runs on a worker thread.
//
// The response's timings are, in order: "queue" (`queue_seconds`, the
// time the job waited for a worker), "decode", core's stages, "encode"
// (the result's conversion, maps included).
// Errors: INVALID_ARGUMENT naming the wire field for a bad frame, core's
// errors (e.g. NOT_FOUND without a support plane), and whatever
// `interrupt` returns (DEADLINE_EXCEEDED, CANCELLED).
absl::StatusOr<v1::DetectResponse> HandleDetect(
    const v1::DetectRequest& request, const DetectOptions& options,
    const FrameLimits& limits, const InterruptCheck& interrupt,
    double queue_seconds);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_HANDLE_DETECT_H_
