#include "server/handle_detect.h"

#include <string>

#include "core/base/status_macros.h"
#include "server/clock.h"
#include "server/convert.h"

namespace fovea::server {

absl::StatusOr<v1::DetectResponse> HandleDetect(
    const v1::DetectRequest& request, const DetectOptions& options,
    const FrameLimits& limits, const InterruptCheck& interrupt,
    double queue_seconds) {
  Clock::time_point start = Clock::now();
  FOVEA_ASSIGN_OR_RETURN(
      RgbdFrame frame,
      DecodeFrame(ToRawFrame(request.frame()), limits, interrupt));
  const double decode_seconds = SecondsSince(start);
  if (interrupt) {
    FOVEA_RETURN_IF_ERROR(interrupt());
  }

  FOVEA_ASSIGN_OR_RETURN(DetectResult result,
                         RunDetect(frame, options, interrupt));

  start = Clock::now();
  FOVEA_ASSIGN_OR_RETURN(v1::DetectResponse response,
                         ToDetectResponse(result, request));
  const double encode_seconds = SecondsSince(start);

  // Put "queue" and "decode" before core's stages, "encode" after.
  google::protobuf::RepeatedPtrField<v1::StageTiming> timings;
  auto add = [&timings](std::string stage, double seconds) {
    v1::StageTiming* timing = timings.Add();
    timing->set_stage(std::move(stage));
    timing->set_seconds(seconds);
  };
  add("queue", queue_seconds);
  add("decode", decode_seconds);
  for (const v1::StageTiming& timing : response.timings()) {
    add(timing.stage(), timing.seconds());
  }
  add("encode", encode_seconds);
  response.mutable_timings()->Swap(&timings);
  return response;
}

}  // namespace fovea::server
