#include "server/call_support.h"

namespace fovea::server {

// UNAVAILABLE once the server is shutting down (its drain delay is over).
absl::Status CheckAccepting(const ServiceState& state) {
  if (state.refusing.load()) {
    return absl::UnavailableError("the server is shutting down; retry another");
  }
  return absl::OkStatus();
}

// DEADLINE_EXCEEDED once the client's deadline passed, CANCELLED once the
// call was cancelled, else OK. Safe on any thread.
absl::Status CheckInterrupt(const grpc::CallbackServerContext& context) {
  if (DeadlinePassed(context.raw_deadline())) {
    return absl::DeadlineExceededError("the client's deadline passed");
  }
  if (context.IsCancelled()) {
    return absl::CancelledError(
        "the call was cancelled (by the client, or by a server shutdown)");
  }
  return absl::OkStatus();
}

// Why a call that waits for a worker was cancelled: DEADLINE_EXCEEDED
// when its deadline passed or is due within 100 ms (the client's own timer
// may fire, and its cancellation arrive, before the server's), CANCELLED
// otherwise.
absl::Status AbandonStatus(const grpc::CallbackServerContext& context) {
  const gpr_timespec soon = gpr_time_sub(
      context.raw_deadline(), gpr_time_from_millis(100, GPR_TIMESPAN));
  if (DeadlinePassed(soon)) {
    return absl::DeadlineExceededError("the client's deadline passed");
  }
  return absl::CancelledError("the call was cancelled");
}

// Submits `run` for the call that `gate` guards (see JobGate).
bool SubmitGated(WorkQueue& work, const std::shared_ptr<JobGate>& gate,
                 absl::AnyInvocable<void() &&> run) {
  gate->Submitted();
  const bool accepted = work.TrySubmit(
      [gate, run = std::move(run)]() mutable {
        if (gate->Start()) std::move(run)();
      },
      [gate] { return gate->abandoned(); });
  if (!accepted) gate->Start();  // refused: nobody may abandon it now
  return accepted;
}

absl::Status BusyError(const WorkQueue& work) {
  RecordShed("busy");
  return absl::ResourceExhaustedError(
      absl::StrCat("server busy: ", work.workers(), " frames in work and ",
                   work.queue_capacity(), " queued; retry later"));
}

}  // namespace fovea::server
