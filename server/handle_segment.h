#ifndef FOVEA_SERVER_HANDLE_SEGMENT_H_
#define FOVEA_SERVER_HANDLE_SEGMENT_H_

#include <functional>

#include "absl/status/status.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/segment.h"
#include "fovea/v1/segment.pb.h"
#include "server/clock.h"

namespace fovea::server {

// Hands one message to the stream; a non-OK status (the client has gone)
// stops the work.
using SendMessage = std::function<absl::Status(v1::SegmentResponse)>;

// What a segmentation call's work needs besides its request.
struct SegmentHandlerContext {
  SegmentModels models;  // not owned
  FrameLimits limits;
  InterruptCheck interrupt;  // the client's deadline and cancellation
  SendMessage send;
  Clock::time_point start;  // when the call started
  double queue_seconds = 0.0;
};

// The Segment work of one call, without gRPC: decode the frame (checked
// against the limits), run core's RunSegment with `options` (converted by
// ToSegmentOptions) and send, in order, the seeds message, one message per
// object the moment it is cut out, and the summary (stop_reason DONE or
// MAX_OBJECTS). Objects' seconds_since_request count from `start`.
// Records the stage timings ("queue", "decode" and core's), the time to
// the first object, the objects per request and the stop reason. Runs on
// a worker thread. Errors: INVALID_ARGUMENT naming the field (frame,
// seeds), core's, and whatever the interrupt or send return
// (DEADLINE_EXCEEDED, CANCELLED), after the messages made so far were
// sent.
absl::Status HandleSegment(const v1::SegmentRequest& request,
                           const SegmentOptions& options,
                           const SegmentHandlerContext& context);

// The same for SegmentIncremental: core's RunSegmentIncremental with the
// INC relation model; the summary's stop reason is DONE (the scene is
// exhausted), MAX_OBJECTS or TIME_BUDGET.
absl::Status HandleSegmentIncremental(
    const v1::SegmentIncrementalRequest& request,
    const IncrementalOptions& options, const SegmentHandlerContext& context);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_HANDLE_SEGMENT_H_
