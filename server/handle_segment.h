#ifndef FOVEA_SERVER_HANDLE_SEGMENT_H_
#define FOVEA_SERVER_HANDLE_SEGMENT_H_

#include <functional>

#include "absl/status/status.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/segment.h"
#include "fovea/v1/segment.pb.h"
#include "server/clock.h"

namespace fovea::server {

// Hands one message to the stream; a non-OK status (the client has gone)
// stops the work.
using SendMessage = std::function<absl::Status(v1::SegmentResponse)>;

// The Segment work of one call, without gRPC: decode the frame (checked
// against `limits`), run core's RunSegment with `options` (converted by
// ToSegmentOptions) and `models`, and send, in order, the seeds message,
// one message per object the moment it is cut out, and the summary
// (stop_reason DONE or MAX_OBJECTS). `start` is when the call started:
// objects' seconds_since_request count from it. Records the stage timings
// ("queue", "decode" and core's), the time to the first object and the
// objects per request. Runs on a worker thread.
// Errors: INVALID_ARGUMENT naming the field (frame, seeds), core's, and
// whatever `interrupt` or `send` return (DEADLINE_EXCEEDED, CANCELLED),
// after the messages made so far were sent.
absl::Status HandleSegment(const v1::SegmentRequest& request,
                           const SegmentOptions& options,
                           const SegmentModels& models,
                           const FrameLimits& limits,
                           const InterruptCheck& interrupt,
                           const SendMessage& send, Clock::time_point start,
                           double queue_seconds);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_HANDLE_SEGMENT_H_
