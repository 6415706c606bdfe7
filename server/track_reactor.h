#ifndef FOVEA_SERVER_TRACK_REACTOR_H_
#define FOVEA_SERVER_TRACK_REACTOR_H_

#include <grpcpp/grpcpp.h>

#include <Eigen/Geometry>
#include <optional>

#include "absl/status/statusor.h"
#include "core/track/tracker.h"
#include "fovea/v1/track.pb.h"
#include "server/perception_service.h"
#include "server/work_queue.h"

namespace fovea::server {

// Perception.Track, one reactor per stream. The first message must carry
// TrackOptions (converted as SegmentIncremental's options); every later one
// a TrackFrame. Frames are read as they come: one waits while another is
// processed, and a newer one replaces it (the older is skipped, counted in
// the response's frames_skipped and in fovea_track_frames_total). Each
// processed frame is decoded, tracked (core/track) on a worker of the
// shared queue, and answered with one TrackResponse; the worker is given
// back between frames, so streams and unary calls take turns. An admitted
// stream's frame waits its turn even in a full queue. The stream ends OK when
// the client half-closes and its last frame was answered; INVALID_ARGUMENT
// naming the field for a bad message or frame; RESOURCE_EXHAUSTED when the
// open-stream limits refuse it; CANCELLED when the client sent nothing for
// the idle timeout while none of its frames waited or ran, or stopped
// reading for the stall timeout.
grpc::ServerBidiReactor<grpc::ByteBuffer, v1::TrackResponse>* NewTrackReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context);

// The wire's camera pose as an isometry: INVALID_ARGUMENT naming `field`
// for a non-finite position or a quaternion that is not finite or is zero
// (it is normalised otherwise).
absl::StatusOr<Eigen::Isometry3f> ToIsometry(const v1::Pose& pose,
                                             std::string_view field);

// TrackOptions as core's TrackerOptions (the segmentation's options as
// ToIncrementalOptions converts them; errors name the field).
absl::StatusOr<TrackerOptions> ToTrackerOptions(
    const v1::TrackOptions& options);

// One processed frame on the wire; `sequence` is the client's number,
// `skipped` the stream's frames skipped so far.
v1::TrackResponse ToTrackResponse(const TrackedFrame& frame,
                                  const std::string& request_id,
                                  uint64_t sequence, uint64_t skipped);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_TRACK_REACTOR_H_
