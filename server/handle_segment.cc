#include "server/handle_segment.h"

#include <optional>
#include <utility>

#include "core/base/status_macros.h"
#include "server/convert.h"
#include "server/metrics.h"

namespace fovea::server {
namespace {

v1::StopReason ToStopReason(SegmentStop stop) {
  switch (stop) {
    case SegmentStop::kMaxObjects:
      return v1::STOP_REASON_MAX_OBJECTS;
    case SegmentStop::kTimeBudget:
      return v1::STOP_REASON_TIME_BUDGET;
    case SegmentStop::kDone:
      break;
  }
  return v1::STOP_REASON_DONE;
}

// Decodes the frame, runs `run` with sinks that send each message, then
// sends the summary; records the metrics of `method`.
template <typename Run>
absl::Status Stream(std::string_view method, const v1::Frame& wire_frame,
                    const std::string& request_id,
                    const SegmentHandlerContext& context, Run run) {
  RecordStage("queue", context.queue_seconds);
  const Clock::time_point decode_start = Clock::now();
  FOVEA_ASSIGN_OR_RETURN(
      RgbdFrame frame,
      DecodeFrame(ToRawFrame(wire_frame), context.limits, context.interrupt));
  RecordStage("decode", SecondsSince(decode_start));
  FOVEA_RETURN_IF_ERROR(CheckInterrupt(context.interrupt));
  int objects = 0;
  std::optional<SupportPlane> support;
  SegmentSinks sinks;
  sinks.support = [&](const SupportPlane& plane) {
    support = plane;
    return absl::OkStatus();
  };
  sinks.points = [&](const std::vector<AttentionPoint>& points) {
    return context.send(ToPointsMessage(
        points, request_id, support.has_value() ? &*support : nullptr));
  };
  sinks.object = [&](SegmentedObject object) {
    if (objects++ == 0) RecordFirstObject(method, object.seconds_since_start);
    return context.send(ToObjectMessage(object, request_id));
  };
  absl::StatusOr<SegmentSummary> summary = run(frame, sinks);
  RecordObjectsPerRequest(method, objects);
  if (!summary.ok()) {
    RecordStopReason(
        method, summary.status().code() == absl::StatusCode::kDeadlineExceeded
                    ? "deadline"
                : summary.status().code() == absl::StatusCode::kCancelled
                    ? "cancelled"
                    : "error");
    return summary.status();
  }
  for (const StageTiming& timing : summary->timings) {
    RecordStage(timing.stage, timing.seconds);
  }
  const v1::StopReason reason = ToStopReason(summary->stop);
  RecordStopReason(method, reason == v1::STOP_REASON_MAX_OBJECTS ? "max_objects"
                           : reason == v1::STOP_REASON_TIME_BUDGET
                               ? "time_budget"
                               : "done");
  return context.send(ToSummaryMessage(*summary, reason, request_id));
}

}  // namespace

absl::Status HandleSegment(const v1::SegmentRequest& request,
                           const SegmentOptions& options,
                           const SegmentHandlerContext& context) {
  return Stream("Segment", request.frame(), request.request_id(), context,
                [&](const RgbdFrame& frame, const SegmentSinks& sinks) {
                  return RunSegment(frame, options, context.models, sinks,
                                    context.interrupt, context.start);
                });
}

absl::Status HandleSegmentIncremental(
    const v1::SegmentIncrementalRequest& request,
    const IncrementalOptions& options, const SegmentHandlerContext& context) {
  return Stream(
      "SegmentIncremental", request.frame(), request.request_id(), context,
      [&](const RgbdFrame& frame, const SegmentSinks& sinks) {
        return RunSegmentIncremental(
            frame, options, context.models.IncFor(frame, options.detect.scene),
            sinks, context.interrupt, context.start);
      });
}

}  // namespace fovea::server
