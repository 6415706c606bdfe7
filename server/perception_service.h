#ifndef FOVEA_SERVER_PERCEPTION_SERVICE_H_
#define FOVEA_SERVER_PERCEPTION_SERVICE_H_

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>

#include "core/frame/frame_decode.h"
#include "core/pipeline/segment.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "server/flight_recorder.h"
#include "server/stream_registry.h"
#include "server/work_queue.h"

namespace fovea::server {

// What the server and the calls share while the service runs.
struct ServiceState {
  std::atomic<int> calls{0};          // Perception calls not yet finished
  std::atomic<bool> refusing{false};  // new calls get UNAVAILABLE
};

struct ServiceConfig {
  // Shared with FoveaServer (Shutdown sets `refusing` and waits for
  // `calls`); never null.
  std::shared_ptr<ServiceState> state = std::make_shared<ServiceState>();
  FrameLimits limits;              // largest frame accepted
  uint64_t max_message_bytes = 0;  // reported by GetCapabilities
  // A stream whose client has not taken a message for this long, while the
  // worker has results waiting for it, is cancelled (CANCELLED, counted in
  // fovea_calls_shed_total{reason="stalled_stream"}) and its worker freed.
  std::chrono::milliseconds stream_stall_timeout{5000};
  // Test hook, null in production: called on the worker thread at the
  // start of every Detect job, before the deadline check. Tests block it
  // to fill the queue deterministically.
  std::function<void()> before_detect_job;
  // Test hook, null in production: called on the worker thread at every
  // stage boundary of a Detect job (after decoding, and between core's
  // stages), right before the deadline and cancellation check there.
  // Tests block it to let a deadline pass in the middle of the pipeline.
  std::function<void()> at_stage_boundary;
  // Test hook, null in production: called on gRPC's thread when it tells a
  // Segment or SegmentIncremental call that the call was cancelled (by the
  // client, its deadline or a shutdown), after which the job's checks see
  // it. Tests wait for it before releasing a job they hold, since a
  // client's cancellation reaches the server asynchronously.
  std::function<void()> on_stream_cancelled;
  // The trained models (not owned: they outlive the service) and their
  // (name, version) pairs for GetCapabilities.
  SegmentModels segment_models;
  std::vector<std::pair<std::string, std::string>> model_versions;
  // The flight recorder (not owned: it outlives the service), or null:
  // then no call is recorded. Detect, Segment and SegmentIncremental calls
  // that start work are offered to it as they end (flight_recorder.h).
  FlightRecorder* recorder = nullptr;
  // The open Track streams and their limits (not owned: it outlives the
  // service), or null: then Track is UNIMPLEMENTED.
  StreamRegistry* streams = nullptr;
  // Segment and SegmentIncremental streams whose work is done and whose
  // last messages wait for the client to take them (its idle timeout is
  // stream_stall_timeout: a stream whose client takes nothing for that
  // long is cancelled), not owned; null: the worker waits for them itself.
  StreamRegistry* stalls = nullptr;
};

// fovea.v1.Perception on gRPC's callback API. Handlers are thin: they
// convert, hand the CPU work to the WorkQueue (never running it on gRPC's
// callback threads), and finish the call from the worker through
// ToGrpcStatus. Every call is counted (metrics.h) and logged in one line:
//   call method=Detect request_id="r1" code=OK ms=23.4
// with message="..." added when the code is not OK.
//
// Detect: options are converted on the callback thread (a bad option
// fails at once); the frame is decoded and processed on a worker. A full
// queue is RESOURCE_EXHAUSTED at once. The client's deadline is checked
// when the job starts (a job that expired while queued is not computed)
// and between stages: DEADLINE_EXCEEDED once it passed, CANCELLED when
// the call was cancelled (by the client, or by a shutdown past its grace
// period). An exception thrown in the job completes the call with INTERNAL
// (RESOURCE_EXHAUSTED when out of memory); the server goes on.
// Segment: options converted on the callback thread; the work on a worker
// (RESOURCE_EXHAUSTED at once when the queue is full); messages streamed
// as HandleSegment makes them, the worker blocking while two are
// unwritten (a client that stops reading costs bounded memory); the
// client's deadline and cancellation are checked between stages, between
// objects and inside the methods' loops, and a failed write stops the
// work. What was made before a deadline has been sent; the call then ends
// DEADLINE_EXCEEDED. A call whose stream broke before its last message was
// written ends as its client saw it, DEADLINE_EXCEEDED once the deadline
// passed, else CANCELLED, even when its job had finished.
// SegmentIncremental: the same streaming, with INC's objects in order of
// saliency; also stops on the request's time budget.
// GetCapabilities: BuildCapabilities, computed once.
// Track: a stream of frames, one response per processed frame
// (track_reactor.h).
// Every method parses its request's body itself: a body that is not a
// valid request (truncated, a proto3 string that is not UTF-8, ...) is
// INVALID_ARGUMENT saying what and where, counted and logged like any
// call.
class PerceptionService final : public v1::Perception::CallbackService {
 public:
  // `work` is not owned; it must outlive every call the service starts
  // (the server stops it only after grpc::Server::Shutdown returned).
  PerceptionService(ServiceConfig config, WorkQueue* work);
  ~PerceptionService() override;

 private:
  // The handlers; each parses its request from `body` (see ParseRequest).
  grpc::ServerUnaryReactor* OnDetect(grpc::CallbackServerContext* context,
                                     const grpc::ByteBuffer* body,
                                     v1::DetectResponse* response);
  grpc::ServerWriteReactor<v1::SegmentResponse>* OnSegment(
      grpc::CallbackServerContext* context, const grpc::ByteBuffer* body);
  grpc::ServerWriteReactor<v1::SegmentResponse>* OnSegmentIncremental(
      grpc::CallbackServerContext* context, const grpc::ByteBuffer* body);
  grpc::ServerBidiReactor<grpc::ByteBuffer, v1::TrackResponse>* OnTrack(
      grpc::CallbackServerContext* context);
  grpc::ServerUnaryReactor* OnGetCapabilities(
      grpc::CallbackServerContext* context, const grpc::ByteBuffer* body,
      v1::GetCapabilitiesResponse* response);

  const ServiceConfig config_;
  WorkQueue* const work_;  // not owned
  const v1::GetCapabilitiesResponse capabilities_;
};

}  // namespace fovea::server

#endif  // FOVEA_SERVER_PERCEPTION_SERVICE_H_
