#include "server/track_reactor.h"

#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/base/guarded.h"
#include "core/base/status_macros.h"
#include "core/base/tsan.h"
#include "core/frame/frame_decode.h"
#include "server/call_support.h"
#include "server/convert.h"
#include "server/convert_internal.h"
#include "server/metrics.h"
#include "server/request_parse.h"
#include "server/stream_registry.h"

namespace fovea::server {
namespace {

constexpr std::string_view kMethod = "Track";

v1::TrackState ToProtoState(TrackState state) {
  switch (state) {
    case TrackState::kAppeared:
      return v1::TRACK_STATE_APPEARED;
    case TrackState::kKept:
      return v1::TRACK_STATE_KEPT;
    case TrackState::kMoved:
      return v1::TRACK_STATE_MOVED;
    case TrackState::kGone:
      return v1::TRACK_STATE_GONE;
  }
  return v1::TRACK_STATE_UNSPECIFIED;
}

// See NewTrackReactor. Every member below mutex_ is guarded by it. The
// worker's job and gRPC's reactions share the reactor; it finishes once
// no job is queued or running and no write is in flight, and deletes
// itself in OnDone.
class TrackReactor final
    : public grpc::ServerBidiReactor<grpc::ByteBuffer, v1::TrackResponse> {
 public:
  TrackReactor(const ServiceConfig& config, WorkQueue& work,
               grpc::CallbackServerContext* context)
      : config_(config),
        work_(work),
        context_(context),
        call_(kMethod, "", *config.state) {
    absl::Status admitted = CheckAccepting(*config.state);
    if (admitted.ok() && config.streams == nullptr) {
      admitted = absl::UnimplementedError("Track is not served here");
    }
    if (admitted.ok()) {
      absl::StatusOr<std::shared_ptr<StreamRegistry::Handle>> handle =
          config.streams->Open(context->peer(), [this] { OnIdle(); });
      if (handle.ok()) {
        handle_ = *std::move(handle);
        AddTrackStreams(1);
      } else {
        RecordShed("stream_limit");
        admitted = handle.status();
      }
    }
    TsanHappensBefore(this);
    if (!admitted.ok()) {
      FinishWith(admitted);
      return;
    }
    StartRead(&in_);
  }

  void OnReadDone(bool ok) override {
    TsanHappensAfter(this);
    if (!ok) {  // the client half-closed (or the call ended)
      std::optional<absl::Status> finish;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        reads_done_ = true;
        finish = ReadyToFinishLocked();
      }
      Conclude(finish);
      return;
    }
    handle_->Touch();
    RecordMessageReceived(kMethod);
    auto request = std::make_unique<v1::TrackRequest>();
    absl::Status parsed = ParseRequest(in_, request.get());
    in_.Clear();
    if (parsed.ok()) parsed = Accept(std::move(request));
    if (!parsed.ok()) {
      FinishWith(parsed);
      return;
    }
    // Before StartRead: the next OnReadDone may run on another thread at
    // once, and libgrpc's ordering of the two is invisible to TSan.
    TsanHappensBefore(this);
    StartRead(&in_);
  }

  void OnWriteDone(bool ok) override {
    TsanHappensAfter(this);
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      writing_ = false;
      if (ok) {
        RecordMessageSent(kMethod);
      } else {
        broken_ = true;
      }
      finish = ReadyToFinishLocked();
    }
    changed_.notify_all();
    Conclude(finish);
  }

  void OnCancel() override {
    TsanHappensAfter(this);
    FinishWith(AbandonStatus(*context_));
  }

  void OnDone() override {
    TsanHappensAfter(this);
    if (record_stream_ != 0) {
      RecordedCall end = StreamRecord();
      end.stream_end = true;
      end.code = absl::StatusCodeToString(end_code_);
      end.seconds = SecondsSince(start_);
      config_.recorder->Submit(std::move(end));
    }
    if (handle_ != nullptr) {
      config_.streams->Close(handle_);
      AddTrackStreams(-1);
    }
    TsanHappensBefore(&config_);  // before the service's destruction
    delete this;
  }

 private:
  struct Pending {
    std::unique_ptr<v1::TrackRequest> request;
    Clock::time_point arrived;
  };

  // A message of this stream for the flight recorder (record_stream_).
  RecordedCall StreamRecord() const {
    RecordedCall message;
    message.method = std::string(kMethod);
    message.stream = record_stream_;
    return message;
  }

  // The registry's idle timer fired: nothing came from the client.
  void OnIdle() {
    FinishWith(absl::CancelledError(absl::StrCat(
        "Track: the client sent nothing for ",
        absl::FormatDuration(
            absl::FromChrono(config_.streams->limits().idle_timeout)),
        " while none of its frames waited or ran (--track_idle_timeout_s); "
        "stream closed")));
  }

  // A message read: the options first, then frames.
  absl::Status Accept(std::unique_ptr<v1::TrackRequest> request) {
    if (!tracker_) {
      if (!request->has_options()) {
        return absl::InvalidArgumentError(
            "options: the first message of a Track stream must carry "
            "TrackOptions");
      }
      FOVEA_ASSIGN_OR_RETURN(TrackerOptions options,
                             ToTrackerOptions(request->options()));
      request_id_ = request->options().request_id();
      {
        // The idle timer may end the stream, and log it, on its own thread.
        std::lock_guard<std::mutex> lock(mutex_);
        call_.set_request_id(request_id_);
      }
      tracker_ = std::make_unique<Tracker>(options, config_.segment_models);
      if (config_.recorder != nullptr && config_.recorder->ShouldRecord()) {
        record_stream_ = config_.recorder->NewStream();
        RecordedCall opening = StreamRecord();
        opening.request = std::move(request);
        config_.recorder->Submit(std::move(opening));
      }
      return absl::OkStatus();
    }
    if (!request->has_frame()) {
      return absl::InvalidArgumentError(
          "frame: every message after the first must carry a TrackFrame");
    }
    if (!request->frame().has_frame()) {
      return absl::InvalidArgumentError(
          "frame.frame: missing (colour, depth and intrinsics are required)");
    }
    bool submit = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (broken_ || final_status_) return absl::OkStatus();
      if (pending_) SkipPendingLocked();  // the freshest frame wins
      pending_ = Pending{std::move(request), Clock::now()};
      if (!job_active_) {
        submit = job_active_ = true;
        handle_->SetBusy(true);  // not idle while its frame waits or runs
      }
    }
    if (submit) Submit();
    return absl::OkStatus();
  }

  // The waiting frame is dropped unprocessed, and counted.
  void SkipPendingLocked() {
    pending_.reset();
    ++skipped_;
    RecordTrackFrame("skipped", 0.0);
  }

  // Hands the next frame to a worker. An open stream was admitted (the
  // stream limits) and holds at most one job: its frame waits its turn in
  // the queue even when the queue is full, so that a client sending a frame
  // after each answer always gets one. Only a stopping queue skips it.
  void Submit() {
    if (work_.SubmitAdmitted([this] { RunOne(); })) return;
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_) SkipPendingLocked();
      job_active_ = false;
      handle_->SetBusy(false);
      finish = ReadyToFinishLocked();
    }
    Conclude(finish);
  }

  // On a worker: one frame.
  void RunOne() {
    std::optional<Pending> frame;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!broken_) frame = std::move(pending_);
      pending_.reset();
    }
    absl::Status status = absl::OkStatus();
    if (frame) {
      status = Guarded(kMethod, [&] { return Process(*frame); });
    }
    if (!status.ok()) FinishWith(status);
    bool again = false;
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_ && !broken_ && !final_status_) {
        again = true;  // back of the queue: others take their turn
      } else {
        job_active_ = false;
        handle_->SetBusy(false);
        finish = ReadyToFinishLocked();
      }
    }
    if (again) {
      Submit();
      return;
    }
    Conclude(finish);
  }

  absl::Status Process(Pending& pending) {
    const v1::TrackFrame& wire = pending.request->frame();
    const InterruptCheck interrupt = [this] {
      if (config_.at_stage_boundary) config_.at_stage_boundary();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (broken_) return absl::CancelledError("Track: the stream ended");
      }
      return CheckInterrupt(*context_);
    };
    const Clock::time_point decode_start = Clock::now();
    FOVEA_ASSIGN_OR_RETURN(
        RgbdFrame frame,
        DecodeFrame(ToRawFrame(wire.frame()), config_.limits, interrupt));
    RecordStage("decode", SecondsSince(decode_start));
    std::optional<Eigen::Isometry3f> pose;
    if (wire.has_camera_to_world()) {
      FOVEA_ASSIGN_OR_RETURN(
          pose, ToIsometry(wire.camera_to_world(), "frame.camera_to_world"));
    }
    FOVEA_ASSIGN_OR_RETURN(TrackedFrame tracked,
                           tracker_->Process(frame, pose, interrupt));
    uint64_t skipped = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      skipped = skipped_;
    }
    v1::TrackResponse response =
        ToTrackResponse(tracked, request_id_, wire.sequence(), skipped);
    RecordTrackFrame(tracked.reused            ? "reused"
                     : tracked.refined         ? "refined"
                     : !tracked.region.empty() ? "region"
                                               : "segmented",
                     SecondsSince(pending.arrived));
    std::unique_ptr<v1::TrackResponse> recorded;
    if (record_stream_ != 0) {
      recorded = std::make_unique<v1::TrackResponse>(response);
    }
    FOVEA_RETURN_IF_ERROR(Send(std::move(response)));
    if (recorded) {
      // The frame, done with, and its answer go to the recorder.
      RecordedCall frame = StreamRecord();
      frame.frame = std::move(pending.request);
      frame.responses.push_back(std::move(recorded));
      config_.recorder->Submit(std::move(frame));
    }
    return absl::OkStatus();
  }

  // Writes `response` once the previous write is done; CANCELLED when the
  // stream broke or the client took nothing for the stall timeout.
  absl::Status Send(v1::TrackResponse response) {
    std::unique_lock<std::mutex> lock(mutex_);
    const Clock::time_point limit = Clock::now() + config_.stream_stall_timeout;
    if (!changed_.wait_until(lock, limit,
                             [this] { return broken_ || !writing_; })) {
      broken_ = true;
      lock.unlock();
      RecordStalledStream();
      // Ends the write in flight (OnWriteDone(false)), so the stream
      // finishes; the job holds the reactor alive meanwhile.
      context_->TryCancel();
      return absl::CancelledError(absl::StrCat(
          "Track: the client read nothing for ",
          config_.stream_stall_timeout.count(), " ms; stream cancelled"));
    }
    if (broken_) return absl::CancelledError("Track: the stream ended");
    writing_ = true;
    out_ = std::move(response);
    lock.unlock();
    StartWrite(&out_);
    return absl::OkStatus();
  }

  // Ends the stream with `status` (the first one given wins) as soon as no
  // job and no write are in flight.
  void FinishWith(const absl::Status& status) {
    std::optional<absl::Status> finish;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!final_status_) final_status_ = status;
      broken_ = true;
      pending_.reset();
      finish = ReadyToFinishLocked();
    }
    changed_.notify_all();
    Conclude(finish);
  }

  // The status to finish with now, once: when the stream is to end (an
  // error, or the client half-closed with nothing left to answer) and no
  // job or write is in flight.
  std::optional<absl::Status> ReadyToFinishLocked() {
    if (finished_) return std::nullopt;
    if (!final_status_ && reads_done_ && !pending_ && !job_active_ &&
        !writing_) {
      final_status_ = absl::OkStatus();
    }
    if (!final_status_ || job_active_ || writing_) return std::nullopt;
    finished_ = true;
    return final_status_;
  }

  // Finishes with `finish` when set: the reactor's last touch, as OnDone
  // may delete it right after.
  void Conclude(const std::optional<absl::Status>& finish) {
    if (!finish) {
      TsanHappensBefore(this);
      return;
    }
    grpc::Status end;
    {
      std::lock_guard<std::mutex> lock(mutex_);  // call_'s request id
      end_code_ = finish->code();
      end = call_.EndStream(*finish);
    }
    TsanHappensBefore(this);
    Finish(end);
  }

  const ServiceConfig& config_;
  WorkQueue& work_;
  grpc::CallbackServerContext* const context_;  // gRPC's, valid until OnDone
  CallRecord call_;  // its request id and end under mutex_
  std::shared_ptr<StreamRegistry::Handle> handle_;  // null when refused
  grpc::ByteBuffer in_;  // the read in flight (reactions run one at a time)
  // Set by the first message, on gRPC's thread; read by the jobs, which
  // are submitted after it.
  std::unique_ptr<Tracker> tracker_;
  std::string request_id_;
  // The stream's id at the flight recorder, 0 when not recorded; set with
  // tracker_.
  uint64_t record_stream_ = 0;
  const Clock::time_point start_ = Clock::now();
  absl::StatusCode end_code_ = absl::StatusCode::kOk;  // set by Conclude

  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<Pending> pending_;  // the freshest frame not yet taken
  bool job_active_ = false;         // a job queued or running
  bool writing_ = false;
  v1::TrackResponse out_;  // being written; guarded by writing_
  bool reads_done_ = false;
  bool broken_ = false;  // no more work: cancelled, failed or finishing
  bool finished_ = false;
  std::optional<absl::Status> final_status_;
  uint64_t skipped_ = 0;
};

}  // namespace

absl::StatusOr<Eigen::Isometry3f> ToIsometry(const v1::Pose& pose,
                                             std::string_view field) {
  const v1::Point3& p = pose.position();
  const v1::Quaternion& q = pose.orientation();
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
    return absl::InvalidArgumentError(
        absl::StrCat(AbslView(field), ".position: not finite"));
  }
  const Eigen::Quaternionf rotation(
      static_cast<float>(q.w()), static_cast<float>(q.x()),
      static_cast<float>(q.y()), static_cast<float>(q.z()));
  const float norm = rotation.norm();
  if (!std::isfinite(norm) || norm < 1e-6f) {
    return absl::InvalidArgumentError(absl::StrCat(
        AbslView(field),
        ".orientation: not a rotation (a finite, non-zero quaternion)"));
  }
  Eigen::Isometry3f out = Eigen::Isometry3f::Identity();
  out.linear() = rotation.normalized().toRotationMatrix();
  out.translation() =
      Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                      static_cast<float>(p.z()));
  return out;
}

absl::StatusOr<TrackerOptions> ToTrackerOptions(
    const v1::TrackOptions& options) {
  v1::SegmentIncrementalRequest as_segment;
  *as_segment.mutable_detect_options() = options.detect_options();
  as_segment.set_max_objects(options.max_objects());
  as_segment.set_time_budget_seconds(options.time_budget_seconds());
  *as_segment.mutable_object_points() = options.object_points();
  TrackerOptions out;
  FOVEA_ASSIGN_OR_RETURN(out.segment, ToIncrementalOptions(as_segment));
  FOVEA_RETURN_IF_ERROR(Validate(out));
  return out;
}

v1::TrackResponse ToTrackResponse(const TrackedFrame& frame,
                                  const std::string& request_id,
                                  uint64_t sequence, uint64_t skipped) {
  v1::TrackResponse out;
  out.set_request_id(request_id);
  out.set_sequence(sequence);
  out.set_frame_index(static_cast<uint64_t>(frame.frame_index));
  out.set_reused(frame.reused);
  out.set_changed_fraction(frame.changed_fraction);
  out.set_joined(static_cast<uint32_t>(frame.joined));
  out.set_split(static_cast<uint32_t>(frame.split));
  out.set_refined(frame.refined);
  if (!frame.region.empty()) {
    v1::BoundingBox* region = out.mutable_segmented_region();
    region->set_u(static_cast<uint32_t>(frame.region.x));
    region->set_v(static_cast<uint32_t>(frame.region.y));
    region->set_width(static_cast<uint32_t>(frame.region.width));
    region->set_height(static_cast<uint32_t>(frame.region.height));
  }
  out.set_frames_skipped(skipped);
  out.set_seconds(frame.seconds);
  for (const StageTiming& timing : frame.timings) {
    v1::StageTiming* t = out.add_timings();
    t->set_stage(timing.stage);
    t->set_seconds(timing.seconds);
  }
  for (const TrackedObject& o : frame.objects) {
    v1::TrackedObject* wire = out.add_objects();
    wire->set_track_id(static_cast<uint64_t>(o.track_id));
    wire->set_state(ToProtoState(o.state));
    wire->set_frames_seen(static_cast<uint32_t>(o.frames_seen));
    *wire->mutable_world_centroid() =
        convert_internal::ToPoint3(o.world_centroid);
    if (o.state == TrackState::kGone) {
      *wire->mutable_object()->mutable_centroid() =
          convert_internal::ToPoint3(o.object.centroid);
    } else {
      *wire->mutable_object() = ToObjectMessage(o.object, request_id).object();
    }
  }
  return out;
}

grpc::ServerBidiReactor<grpc::ByteBuffer, v1::TrackResponse>* NewTrackReactor(
    const ServiceConfig& config, WorkQueue& work,
    grpc::CallbackServerContext* context) {
  return new TrackReactor(config, work, context);
}

}  // namespace fovea::server
