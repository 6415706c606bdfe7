#include "server/perception_service.h"

#include <algorithm>
#include <atomic>
#include <chrono>
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
#include "server/log.h"
#include "server/metrics.h"
#include "server/request_parse.h"
#include "server/segment_reactor.h"
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
  return NewSegmentReactor(config_, *work_, context, std::move(request),
                           parsed);
}

grpc::ServerWriteReactor<v1::SegmentResponse>*
PerceptionService::OnSegmentIncremental(grpc::CallbackServerContext* context,
                                        const grpc::ByteBuffer* body) {
  TsanHappensAfter(&config_);
  auto [request, parsed] =
      ParseUnlessBusy<v1::SegmentIncrementalRequest>(*work_, body);
  return NewSegmentIncrementalReactor(config_, *work_, context,
                                      std::move(request), parsed);
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
