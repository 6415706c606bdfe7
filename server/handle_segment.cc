#include "server/handle_segment.h"

#include <utility>

#include "server/convert.h"
#include "server/metrics.h"

namespace fovea::server {

absl::Status HandleSegment(const v1::SegmentRequest& request,
                           const SegmentOptions& options,
                           const SegmentModels& models,
                           const FrameLimits& limits,
                           const InterruptCheck& interrupt,
                           const SendMessage& send, Clock::time_point start,
                           double queue_seconds) {
  RecordStage("queue", queue_seconds);
  const Clock::time_point decode_start = Clock::now();
  absl::StatusOr<RgbdFrame> frame =
      DecodeFrame(ToRawFrame(request.frame()), limits);
  if (!frame.ok()) return frame.status();
  RecordStage("decode", SecondsSince(decode_start));
  if (absl::Status status = CheckInterrupt(interrupt); !status.ok()) {
    return status;
  }

  const std::string& id = request.request_id();
  int objects = 0;
  SegmentSinks sinks;
  sinks.points = [&](const std::vector<AttentionPoint>& points) {
    return send(ToPointsMessage(points, id));
  };
  sinks.object = [&](SegmentedObject object) {
    if (objects++ == 0) {
      RecordFirstObject("Segment", object.seconds_since_start);
    }
    return send(ToObjectMessage(object, id));
  };
  absl::StatusOr<SegmentSummary> summary =
      RunSegment(*frame, options, models, sinks, interrupt, start);
  RecordObjectsPerRequest("Segment", objects);
  if (!summary.ok()) return summary.status();
  for (const StageTiming& timing : summary->timings) {
    RecordStage(timing.stage, timing.seconds);
  }
  const v1::StopReason reason =
      summary->stop == SegmentStop::kMaxObjects ? v1::MAX_OBJECTS : v1::DONE;
  return send(ToSummaryMessage(*summary, reason, id));
}

}  // namespace fovea::server
