#ifndef FOVEA_SERVER_CALL_SUPPORT_H_
#define FOVEA_SERVER_CALL_SUPPORT_H_

// What every Perception call shares (perception_service.cc): its record
// (metrics and the log line), admission, the interrupt checks, the gate
// between a queued job and the call's reactions, and parsing its body.

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "absl/functional/any_invocable.h"
#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/base/status_macros.h"
#include "core/base/tsan.h"
#include "server/clock.h"
#include "server/log.h"
#include "server/metrics.h"
#include "server/perception_service.h"
#include "server/request_parse.h"
#include "server/status_util.h"
#include "server/work_queue.h"

namespace fovea::server {

// Longest request_id written to the log; the id comes from the client.
constexpr size_t kMaxLoggedRequestId = 128;

// The metrics and the log line of one call: started when constructed,
// handled at End*. Each call ends exactly once.
class CallRecord {
 public:
  CallRecord(std::string_view method, std::string_view request_id,
             ServiceState& state)
      : method_(method),
        request_id_(request_id.substr(0, kMaxLoggedRequestId)),
        start_(Clock::now()),
        state_(state) {
    state_.calls.fetch_add(1);
    RecordCallStarted(method_);
    RecordMessageReceived(method_);
    IncrementInflight();
  }

  // The call is over for gRPC too (the reactor is deleted after OnDone):
  // only now does it stop counting in ServiceState::calls, so a shutdown
  // that waits for calls to reach 0 never cancels an answer still being
  // sent.
  // This is a call's last touch of the ServiceState, after its reactor's
  // OnDone: the server destroys the state after gRPC's shutdown, which
  // waits for every call's OnDone (an ordering TSan cannot see in libgrpc;
  // FoveaServer::Shutdown states the other half).
  ~CallRecord() {
    state_.calls.fetch_sub(1);
    TsanHappensBefore(&state_);
  }
  CallRecord(const CallRecord&) = delete;
  CallRecord& operator=(const CallRecord&) = delete;

  // A unary call: one message sent when OK.
  grpc::Status EndUnary(const absl::Status& status) {
    if (status.ok()) RecordMessageSent(method_);
    return End(status);
  }

  // A server stream; its messages were counted as they were sent.
  grpc::Status EndStream(const absl::Status& status) { return End(status); }

  // The request id a stream's first message gave (Track's options arrive
  // after the call started), for the call's log line.
  void set_request_id(std::string_view request_id) {
    request_id_ = std::string(request_id.substr(0, kMaxLoggedRequestId));
  }

 private:
  grpc::Status End(const absl::Status& status) {
    const double seconds = SecondsSince(start_);
    RecordCallHandled(method_, status.code(), seconds);
    DecrementInflight();
    std::string line = absl::StrFormat(
        "call method=%s request_id=\"%s\" code=%s ms=%.1f", method_,
        absl::CEscape(request_id_), GrpcCodeName(status.code()), seconds * 1e3);
    if (!status.ok()) {
      absl::StrAppend(&line, " message=\"", absl::CEscape(status.message()),
                      "\"");
    }
    LogInfo(line);
    return ToGrpcStatus(status);
  }

  const std::string_view method_;  // a string literal
  std::string request_id_;
  const Clock::time_point start_;
  ServiceState& state_;
};

// UNAVAILABLE once the server is shutting down (its drain delay is over).
absl::Status CheckAccepting(const ServiceState& state);

// DEADLINE_EXCEEDED once the client's deadline passed, CANCELLED once the
// call was cancelled, else OK. Safe on any thread.
absl::Status CheckInterrupt(const grpc::CallbackServerContext& context);

// Why a call that waits for a worker was cancelled: DEADLINE_EXCEEDED
// when its deadline passed or is due within 100 ms (the client's own timer
// may fire, and its cancellation arrive, before the server's), CANCELLED
// otherwise.
absl::Status AbandonStatus(const grpc::CallbackServerContext& context);

// What every frame-carrying call checks first: the server still accepts
// calls, its body parsed (`parsed`, from ParseRequest), and the request
// has a frame.
template <typename Request>
absl::Status AdmitFrameCall(const ServiceState& state,
                            const absl::Status& parsed,
                            const Request& request) {
  FOVEA_RETURN_IF_ERROR(CheckAccepting(state));
  if (!parsed.ok()) return parsed;
  if (!request.has_frame()) {
    return absl::InvalidArgumentError(
        "frame: missing (colour, depth and intrinsics are required)");
  }
  return absl::OkStatus();
}

// Who finishes a call whose job waits for a worker: the worker, once it
// starts the job, or the reaction to the client leaving (its deadline
// passed, it cancelled), if that comes first. Whichever wins the exchange
// finishes the call; an abandoned job never runs and frees its queue slot
// (WorkQueue::TrySubmit). Shared by the reactor and its job, so the job
// can look at it after the reactor is gone.
class JobGate {
 public:
  // Before submitting.
  void Submitted() { state_.store(kWaiting); }
  // The worker: true when it may run the job (and touch the reactor).
  bool Start() { return Exchange(kStarted); }
  // A reaction: true when it must finish the call itself.
  bool Abandon() { return Exchange(kAbandoned); }
  bool abandoned() const { return state_.load() == kAbandoned; }

 private:
  static constexpr int kIdle = 0;  // not submitted (or refused)
  static constexpr int kWaiting = 1;
  static constexpr int kStarted = 2;
  static constexpr int kAbandoned = 3;
  bool Exchange(int to) {
    int expected = kWaiting;
    return state_.compare_exchange_strong(expected, to);
  }
  std::atomic<int> state_{kIdle};
};

// Submits `run` for the call that `gate` guards (see JobGate).
bool SubmitGated(WorkQueue& work, const std::shared_ptr<JobGate>& gate,
                 absl::AnyInvocable<void() &&> run);

// The request as parsed from its body, and how the parse went; the body's
// slices are released once parsed. gRPC allocated the body (non-const) and
// destroys it only when the call is done, so it may be cleared here.
template <typename Request>
std::pair<std::unique_ptr<Request>, absl::Status> Parse(
    const grpc::ByteBuffer* body) {
  auto request = std::make_unique<Request>();
  absl::Status parsed = ParseRequest(*body, request.get());
  const_cast<grpc::ByteBuffer*>(body)->Clear();
  return {std::move(request), std::move(parsed)};
}

// RESOURCE_EXHAUSTED "server busy: ..., retry later", counted in
// fovea_calls_shed_total{reason="busy"}: a call the work queue cannot take.
absl::Status BusyError(const WorkQueue& work);

// Parse, unless the work queue is full now: then the call is refused as
// BusyError before its body is parsed (the body is released unread), so a
// refusal under overload costs next to nothing. A call parsed because
// the queue had room may still be refused when it is submitted.
template <typename Request>
std::pair<std::unique_ptr<Request>, absl::Status> ParseUnlessBusy(
    const WorkQueue& work, const grpc::ByteBuffer* body) {
  if (work.Full()) {
    const_cast<grpc::ByteBuffer*>(body)->Clear();
    return {std::make_unique<Request>(), BusyError(work)};
  }
  return Parse<Request>(body);
}

}  // namespace fovea::server

#endif  // FOVEA_SERVER_CALL_SUPPORT_H_
