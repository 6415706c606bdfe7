#include "server/perception_service.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "core/base/check.h"
#include "core/base/guarded.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/base/tsan.h"
#include "server/call_support.h"
#include "server/capabilities.h"
#include "server/clock.h"
#include "server/convert.h"
#include "server/handle_detect.h"
#include "server/handle_segment.h"
#include "server/log.h"
#include "server/metrics.h"
#include "server/request_parse.h"
#include "server/status_util.h"
#include "server/track_reactor.h"

namespace fovea::server {
namespace {

// `method`'s index in the service (the generated CallbackService registers
// its handlers in the contract's order), from its descriptor.
int MethodIndex(const std::string& method) {
  const google::protobuf::MethodDescriptor* found =
      PerceptionDescriptor().FindMethodByName(method);
  FOVEA_CHECK(found != nullptr);
  return found->index();
}

// One Detect call. Converts the options at once, then runs on a worker;
// finishes exactly once and deletes itself in OnDone.
class DetectReactor final : public grpc::ServerUnaryReactor {
 public:
  DetectReactor(const ServiceConfig& config, WorkQueue& work,
                grpc::CallbackServerContext* context,
                std::unique_ptr<v1::DetectRequest> request,
                const absl::Status& parsed, v1::DetectResponse* response)
      : config_(config),
        context_(context),
        request_(std::move(request)),
        response_(response),
        call_("Detect", request_->request_id(), *config.state) {
    if (absl::Status s = AdmitFrameCall(*config.state, parsed, *request_);
        !s.ok()) {
      Complete(s);
      return;
    }
    absl::StatusOr<DetectOptions> options =
        ToDetectOptions(request_->options());
    if (!options.ok()) {
      Complete(options.status());
      return;
    }
    options_ = *std::move(options);
    submitted_ = Clock::now();
    record_ = config.recorder != nullptr && config.recorder->ShouldRecord();
    TsanHappensBefore(this);  // before the reactions (OnCancel)
    // The worker sees all of this through the queue's lock.
    if (!SubmitGated(work, gate_, [this] { Run(); })) {
      Complete(BusyError(work));
    }
  }

  // The client left (or its deadline passed): a job still waiting for a
  // worker is abandoned and the call ends now; a running one stops at its
  // next stage boundary.
  void OnCancel() override {
    TsanHappensAfter(this);
    if (gate_->Abandon()) {
      RecordAbandonedInQueue();
      Complete(AbandonStatus(*context_));
      return;
    }
    TsanHappensBefore(this);
  }

  // gRPC calls OnDone after Finish, on any of its threads; the request and
  // response it owns are deleted right after. (The Tsan* calls tell
  // ThreadSanitizer about that ordering, which libgrpc makes where TSan
  // cannot see it; they are empty in other builds.)
  void OnDone() override {
    TsanHappensAfter(this);
    if (record_) {
      // The call is over: its request and answer go to the recorder (the
      // response is gRPC's, deleted after this; it was sent already).
      std::vector<std::unique_ptr<const google::protobuf::Message>> sent;
      if (end_code_ == absl::StatusCode::kOk) {
        auto response = std::make_unique<v1::DetectResponse>();
        response->Swap(response_);
        sent.push_back(std::move(response));
      }
      config_.recorder->Submit(EndedCall("Detect", std::move(request_),
                                         std::move(sent), end_code_,
                                         SecondsSince(start_)));
    }
    TsanHappensBefore(&config_);  // before the service's destruction
    delete this;
  }

 private:
  // On a worker thread. Completes the call exactly once, whatever
  // happens: the call's one exception boundary turns what anything in the
  // job throws (decoding, core, conversion, the test hooks) into
  // RESOURCE_EXHAUSTED (out of memory) or INTERNAL instead of leaving the
  // call unfinished or reaching the WorkQueue.
  void Run() {
    Complete(Guarded("Detect", [this] { return Compute(); }));
  }

  // The job's work; fills *response_ when OK. May throw.
  absl::Status Compute() {
    const double queue_seconds = SecondsSince(submitted_);
    RecordQueueWait(queue_seconds);
    if (config_.before_detect_job) config_.before_detect_job();
    FOVEA_RETURN_IF_ERROR(CheckInterrupt(*context_));
    absl::StatusOr<v1::DetectResponse> response = HandleDetect(
        *request_, options_, config_.limits,
        [this] {
          if (config_.at_stage_boundary) config_.at_stage_boundary();
          return CheckInterrupt(*context_);
        },
        queue_seconds);
    if (!response.ok()) return response.status();
    for (const v1::StageTiming& timing : response->timings()) {
      RecordStage(timing.stage(), timing.seconds());
    }
    *response_ = *std::move(response);
    return absl::OkStatus();
  }

  // The last thing the reactor does: OnDone may delete it right after.
  void Complete(const absl::Status& status) {
    end_code_ = status.code();
    const grpc::Status end = call_.EndUnary(status);
    TsanHappensBefore(this);  // before OnDone
    Finish(end);
  }

  const ServiceConfig& config_;  // the service's; outlives every call
  // gRPC's, valid until OnDone.
  grpc::CallbackServerContext* const context_;
  // Read only here; moved to the recorder in OnDone, when recorded (which
  // takes the pixels out of it as it writes them to files).
  std::unique_ptr<v1::DetectRequest> request_;
  v1::DetectResponse* const response_;  // gRPC's, valid until OnDone
  CallRecord call_;
  const Clock::time_point start_ = Clock::now();
  DetectOptions options_;
  Clock::time_point submitted_;
  bool record_ = false;  // offered to config_.recorder when done
  absl::StatusCode end_code_ = absl::StatusCode::kUnknown;
  const std::shared_ptr<JobGate> gate_ = std::make_shared<JobGate>();
};

// One Segment call: options converted at once, the work on a worker, the
// messages written one at a time as the worker makes them. The worker
// waits while kMaxPendingMessages are unwritten (a client that stops
// reading holds at most that many messages in memory) and stops when the
// client cancels or a write fails. A client that takes no message for
// config.stream_stall_timeout while the worker waits for room has its
// stream cancelled: a slow reader holds a worker for at most that long.
// The last messages (at most kMaxPendingMessages) do not hold the worker:
// they wait for the client under a stall watch (config.stalls), which
// cancels the stream after the same timeout. Finishes exactly once, after every
// queued message was written; deletes itself in OnDone, which gRPC calls
// only after Finish, and Finish only comes after the worker's last touch.
template <typename Request, typename Options>
class StreamReactor final
    : public grpc::ServerWriteReactor<v1::SegmentResponse> {
 public:
  // Converts the request's options (a bad one fails the call at once).
  using Convert = absl::StatusOr<Options> (*)(const Request&);
  // The work of one call (HandleSegment, HandleSegmentIncremental).
  using Handle = absl::Status (*)(const Request&, const Options&,
                                  const SegmentHandlerContext&);

  StreamReactor(std::string_view method, Convert convert, Handle handle,
                const ServiceConfig& config, WorkQueue& work,
                grpc::CallbackServerContext* context,
                std::unique_ptr<Request> request, const absl::Status& parsed)
      : method_(method),
        handle_(handle),
        config_(config),
        context_(context),
        request_(std::move(request)),
        call_(method, request_->request_id(), *config.state),
        start_(Clock::now()) {
    if (absl::Status s = AdmitFrameCall(*config.state, parsed, *request_);
        !s.ok()) {
      FinishOnce(s);
      return;
    }
    absl::StatusOr<Options> options = convert(*request_);
    if (!options.ok()) {
      FinishOnce(options.status());
      return;
    }
    options_ = *std::move(options);
    record_ = config.recorder != nullptr && config.recorder->ShouldRecord();
    TsanHappensBefore(this);  // before the reactions (OnCancel, ...)
    if (!SubmitGated(work, gate_, [this] { Run(); })) {
      FinishOnce(BusyError(work));
    }
  }

  // Each reaction starts with TsanHappensAfter(this) and ends with
  // TsanHappensBefore: gRPC runs them one after another, and after the
  // constructor, on any of its threads (see DetectReactor::OnDone).
  void OnWriteDone(bool ok) override {
    TsanHappensAfter(this);
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      writing_ = false;
      if (!ok) {
        broken_ = true;
        pending_.clear();
        pending_bytes_ = 0;
      } else {
        RecordMessageSent(method_);
        if (stall_watch_) stall_watch_->Touch();  // the client took one
      }
      if (!pending_.empty()) {
        StartNextWriteLocked();
      } else if (final_status_ && !finished_) {
        finished_ = true;
        finish = EndStatusLocked(*final_status_);
      }
    }
    changed_.notify_all();
    if (finish) {
      EndCall(*finish);
    } else {
      TsanHappensBefore(this);
    }
  }

  void OnCancel() override {
    TsanHappensAfter(this);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      broken_ = true;
    }
    changed_.notify_all();
    if (config_.on_stream_cancelled) config_.on_stream_cancelled();
    if (gate_->Abandon()) {  // still waiting for a worker: end it now
      RecordAbandonedInQueue();
      FinishOnce(AbandonStatus(*context_));
      return;
    }
    TsanHappensBefore(this);
  }

  void OnDone() override {
    TsanHappensAfter(this);
    if (record_) {
      std::vector<std::unique_ptr<const google::protobuf::Message>> sent;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        sent = std::move(recorded_);
      }
      config_.recorder->Submit(EndedCall(std::string(method_),
                                         std::move(request_), std::move(sent),
                                         end_code_, SecondsSince(start_)));
    }
    TsanHappensBefore(&config_);  // before the service's destruction
    delete this;
  }

 private:
  // At most this many messages, and this many bytes of them (one message
  // always fits), wait unwritten before the worker blocks: an object's
  // mask is usually a few kB of run lengths.
  static constexpr size_t kMaxPendingMessages = 16;
  static constexpr size_t kMaxPendingBytes = 2 << 20;

  // On a worker thread.
  void Run() {
    FinishOnce(Guarded(method_, [this] {
      absl::Status status = Compute();
      if (status.ok()) LeaveTheLastWrites();
      return status;
    }));
  }

  // After the job's last Send: the messages still unwritten are left to
  // the reactor and the worker goes back to the queue, a stall watch
  // (config.stalls) cancelling the stream should the client take nothing
  // for the stall timeout. Without config.stalls, the worker waits for them
  // itself. Runs before FinishOnce, so the call cannot end meanwhile.
  void LeaveTheLastWrites() {
    if (config_.stalls == nullptr) {
      WaitForTheLastWrites();
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (broken_ || (!writing_ && pending_.empty())) return;
    }
    absl::StatusOr<std::shared_ptr<StreamRegistry::Handle>> watch =
        config_.stalls->Open(context_->peer(), [this] { OnStalled(); });
    if (!watch.ok()) {
      WaitForTheLastWrites();
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    stall_watch_ = *std::move(watch);
  }

  // The stall watch fired (on its own thread, before EndCall closed it):
  // the client took nothing for the stall timeout.
  void OnStalled() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (broken_ || (!writing_ && pending_.empty())) return;
      broken_ = true;
      stalled_ = true;
    }
    changed_.notify_all();
    // Ends the write in flight (OnWriteDone(false)), which finishes.
    context_->TryCancel();
  }

  absl::Status Compute() {
    const double queue_seconds = SecondsSince(start_);
    RecordQueueWait(queue_seconds);
    FOVEA_RETURN_IF_ERROR(CheckInterrupt(*context_));
    SegmentHandlerContext handler;
    handler.models = config_.segment_models;
    handler.limits = config_.limits;
    handler.interrupt = [this] {
      if (config_.at_stage_boundary) config_.at_stage_boundary();
      return CheckInterrupt(*context_);
    };
    handler.send = [this](v1::SegmentResponse message) {
      return Send(std::move(message));
    };
    handler.start = start_;
    handler.queue_seconds = queue_seconds;
    return handle_(*request_, options_, handler);
  }

  // Queues one message; blocks while kMaxPendingMessages wait. CANCELLED
  // once the client has gone or stalled.
  absl::Status Send(v1::SegmentResponse message) {
    std::unique_lock<std::mutex> lock(mutex_);
    const size_t bytes = message.ByteSizeLong();
    WaitUnlessStalled(lock, [this, bytes] {
      return broken_ || pending_.empty() ||
             (pending_.size() < kMaxPendingMessages &&
              pending_bytes_ + bytes <= kMaxPendingBytes);
    });
    if (broken_) return BrokenStatus();
    if (record_) {
      recorded_.push_back(std::make_unique<v1::SegmentResponse>(message));
    }
    pending_bytes_ += bytes;
    pending_.push_back(std::move(message));
    if (!writing_) StartNextWriteLocked();
    return absl::OkStatus();
  }

  void StartNextWriteLocked() {
    current_ = std::move(pending_.front());
    pending_.pop_front();
    pending_bytes_ -= std::min(pending_bytes_, current_.ByteSizeLong());
    writing_ = true;
    write_started_ = Clock::now();
    StartWrite(&current_);
  }

  // Waits until `done`, unless the write in progress takes longer than the
  // stall timeout: then the stream is marked broken and cancelled (which
  // wakes every waiter) and the wait ends.
  template <typename Predicate>
  void WaitUnlessStalled(std::unique_lock<std::mutex>& lock, Predicate done) {
    while (!done()) {
      const Clock::time_point limit =
          write_started_ + config_.stream_stall_timeout;
      if (changed_.wait_until(lock, limit, done)) return;
      if (writing_ && Clock::now() >= limit && !broken_) {
        broken_ = true;
        stalled_ = true;
        lock.unlock();
        RecordStalledStream();
        context_->TryCancel();  // the reactor is alive: the job holds it
        changed_.notify_all();
        lock.lock();
      }
    }
  }

  // After the job's last Send: holds the worker until the client took
  // every message (or stalled), so that a call ends with what it sent.
  void WaitForTheLastWrites() {
    std::unique_lock<std::mutex> lock(mutex_);
    WaitUnlessStalled(
        lock, [this] { return broken_ || (!writing_ && pending_.empty()); });
  }

  // Finishes now when nothing is being written, else after the last write.
  void FinishOnce(const absl::Status& status) {
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (finished_ || final_status_) return;
      final_status_ = status;
      if (!writing_ && pending_.empty()) {
        finished_ = true;
        finish = EndStatusLocked(status);
      }
    }
    if (finish) EndCall(*finish);
  }

  // Records the call's end and finishes it: the reactor's last touch, as
  // OnDone may delete it right after.
  void EndCall(const absl::Status& status) {
    std::shared_ptr<StreamRegistry::Handle> watch;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      watch = std::move(stall_watch_);
    }
    // Waits for OnStalled in progress; none comes after.
    if (watch) config_.stalls->Close(watch);
    end_code_ = status.code();
    const grpc::Status end = call_.EndStream(status);
    TsanHappensBefore(this);
    Finish(end);
  }

  // Why the stream broke (the client cancelled, went away or stopped
  // reading, or its deadline passed): DEADLINE_EXCEEDED once the deadline
  // passed, else CANCELLED.
  absl::Status BrokenStatus() const {
    if (stalled_) {
      return absl::CancelledError(absl::StrCat(
          "the client read nothing for ", config_.stream_stall_timeout.count(),
          " ms; stream cancelled"));
    }
    absl::Status status = CheckInterrupt(*context_);
    if (!status.ok()) return status;
    return absl::CancelledError("the client cancelled or stopped reading");
  }

  // The status the call ends with when the job ended with `status`: a job
  // that succeeded but whose stream broke before its last message was
  // written did not deliver, so the call ends as the client saw it.
  absl::Status EndStatusLocked(const absl::Status& status) const {
    return status.ok() && broken_ ? BrokenStatus() : status;
  }

  const std::string_view method_;  // a string literal
  const Handle handle_;
  const ServiceConfig& config_;
  grpc::CallbackServerContext* const context_;  // gRPC's, valid until OnDone
  // Read only here; moved to the recorder in OnDone, when recorded (which
  // takes the pixels out of it as it writes them to files).
  std::unique_ptr<Request> request_;
  CallRecord call_;
  const Clock::time_point start_;
  Options options_;
  bool record_ = false;  // offered to config_.recorder when done
  absl::StatusCode end_code_ = absl::StatusCode::kUnknown;
  // When recorded, a copy of each message sent; guarded by mutex_.
  std::vector<std::unique_ptr<const google::protobuf::Message>> recorded_;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<v1::SegmentResponse> pending_;  // guarded by mutex_
  size_t pending_bytes_ = 0;                 // guarded by mutex_
  v1::SegmentResponse current_;      // being written; guarded by writing_
  bool writing_ = false;             // guarded by mutex_
  bool broken_ = false;              // guarded by mutex_
  bool stalled_ = false;             // guarded by mutex_
  Clock::time_point write_started_;  // guarded by mutex_
  bool finished_ = false;            // guarded by mutex_
  std::optional<absl::Status> final_status_;  // guarded by mutex_
  // Open while the last messages wait for the client (LeaveTheLastWrites);
  // guarded by mutex_.
  std::shared_ptr<StreamRegistry::Handle> stall_watch_;
  const std::shared_ptr<JobGate> gate_ = std::make_shared<JobGate>();
};

}  // namespace

PerceptionService::PerceptionService(ServiceConfig config, WorkQueue* work)
    : config_(std::move(config)), work_(work), capabilities_([this] {
        v1::GetCapabilitiesResponse c = BuildCapabilities(
            config_.limits, config_.max_message_bytes, config_.model_versions);
        c.set_track(config_.streams != nullptr);
        return c;
      }()) {
  // Each method takes its request's bytes (see ParseRequest) and answers
  // typed messages: the handlers the generated CallbackService registered
  // are replaced, in the service's method order, with handlers of the
  // same kind (grpc::internal's, which generated code uses too) whose
  // request type is grpc::ByteBuffer, which gRPC never fails to
  // deserialise.
  MarkMethodCallback(
      MethodIndex("Detect"),
      new grpc::internal::CallbackUnaryHandler<grpc::ByteBuffer,
                                               v1::DetectResponse>(
          [this](grpc::CallbackServerContext* context,
                 const grpc::ByteBuffer* body, v1::DetectResponse* response) {
            return OnDetect(context, body, response);
          }));
  MarkMethodCallback(
      MethodIndex("Segment"),
      new grpc::internal::CallbackServerStreamingHandler<grpc::ByteBuffer,
                                                         v1::SegmentResponse>(
          [this](grpc::CallbackServerContext* context,
                 const grpc::ByteBuffer* body) {
            return OnSegment(context, body);
          }));
  MarkMethodCallback(
      MethodIndex("SegmentIncremental"),
      new grpc::internal::CallbackServerStreamingHandler<grpc::ByteBuffer,
                                                         v1::SegmentResponse>(
          [this](grpc::CallbackServerContext* context,
                 const grpc::ByteBuffer* body) {
            return OnSegmentIncremental(context, body);
          }));
  MarkMethodCallback(
      MethodIndex("GetCapabilities"),
      new grpc::internal::CallbackUnaryHandler<grpc::ByteBuffer,
                                               v1::GetCapabilitiesResponse>(
          [this](grpc::CallbackServerContext* context,
                 const grpc::ByteBuffer* body,
                 v1::GetCapabilitiesResponse* response) {
            return OnGetCapabilities(context, body, response);
          }));
  MarkMethodCallback(MethodIndex("Track"),
                     new grpc::internal::CallbackBidiHandler<grpc::ByteBuffer,
                                                             v1::TrackResponse>(
                         [this](grpc::CallbackServerContext* context) {
                           return OnTrack(context);
                         }));
  // gRPC's threads call the methods below; what was built here (and the
  // work queue before it) happens before, through libgrpc (see
  // DetectReactor::OnDone).
  TsanHappensBefore(&config_);
}

PerceptionService::~PerceptionService() {
  TsanHappensAfter(&config_);  // after every call's OnDone
}

grpc::ServerUnaryReactor* PerceptionService::OnDetect(
    grpc::CallbackServerContext* context, const grpc::ByteBuffer* body,
    v1::DetectResponse* response) {
  TsanHappensAfter(&config_);
  auto [request, parsed] = ParseUnlessBusy<v1::DetectRequest>(*work_, body);
  return new DetectReactor(config_, *work_, context, std::move(request), parsed,
                           response);
}

grpc::ServerWriteReactor<v1::SegmentResponse>* PerceptionService::OnSegment(
    grpc::CallbackServerContext* context, const grpc::ByteBuffer* body) {
  TsanHappensAfter(&config_);
  auto [request, parsed] = ParseUnlessBusy<v1::SegmentRequest>(*work_, body);
  return new StreamReactor<v1::SegmentRequest, SegmentOptions>(
      "Segment", &ToSegmentOptions, &HandleSegment, config_, *work_, context,
      std::move(request), parsed);
}

grpc::ServerWriteReactor<v1::SegmentResponse>*
PerceptionService::OnSegmentIncremental(grpc::CallbackServerContext* context,
                                        const grpc::ByteBuffer* body) {
  TsanHappensAfter(&config_);
  auto [request, parsed] =
      ParseUnlessBusy<v1::SegmentIncrementalRequest>(*work_, body);
  return new StreamReactor<v1::SegmentIncrementalRequest, IncrementalOptions>(
      "SegmentIncremental", &ToIncrementalOptions, &HandleSegmentIncremental,
      config_, *work_, context, std::move(request), parsed);
}

grpc::ServerBidiReactor<grpc::ByteBuffer, v1::TrackResponse>*
PerceptionService::OnTrack(grpc::CallbackServerContext* context) {
  TsanHappensAfter(&config_);
  return NewTrackReactor(config_, *work_, context);
}

grpc::ServerUnaryReactor* PerceptionService::OnGetCapabilities(
    grpc::CallbackServerContext* context, const grpc::ByteBuffer* body,
    v1::GetCapabilitiesResponse* response) {
  TsanHappensAfter(&config_);
  CallRecord call("GetCapabilities", "", *config_.state);
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status status = CheckAccepting(*config_.state);
  if (status.ok()) status = Parse<v1::GetCapabilitiesRequest>(body).second;
  if (status.ok()) *response = capabilities_;
  reactor->Finish(call.EndUnary(status));
  return reactor;
}

}  // namespace fovea::server
