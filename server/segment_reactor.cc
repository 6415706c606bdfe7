#include "server/segment_reactor.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/guarded.h"
#include "core/base/status_macros.h"
#include "core/base/tsan.h"
#include "server/call_support.h"
#include "server/clock.h"
#include "server/convert.h"
#include "server/flight_recorder.h"
#include "server/handle_segment.h"
#include "server/metrics.h"
#include "server/stream_registry.h"

namespace fovea::server {
namespace {

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

grpc::ServerWriteReactor<v1::SegmentResponse>* NewSegmentReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context,
    std::unique_ptr<v1::SegmentRequest> request, const absl::Status& parsed) {
  return new StreamReactor<v1::SegmentRequest, SegmentOptions>(
      "Segment", &ToSegmentOptions, &HandleSegment, config, work, context,
      std::move(request), parsed);
}

grpc::ServerWriteReactor<v1::SegmentResponse>* NewSegmentIncrementalReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context,
    std::unique_ptr<v1::SegmentIncrementalRequest> request,
    const absl::Status& parsed) {
  return new StreamReactor<v1::SegmentIncrementalRequest, IncrementalOptions>(
      "SegmentIncremental", &ToIncrementalOptions, &HandleSegmentIncremental,
      config, work, context, std::move(request), parsed);
}

}  // namespace fovea::server
