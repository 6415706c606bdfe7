// StackedPileOptions (declared in stacked_scene.h): what a pile asks for,
// checked, and the options of each sensor's own frame and of the views
// from above.
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/synth/room.h"
#include "core/synth/stacked_scene.h"

namespace fovea::synth {

absl::Status Validate(const StackedPileOptions& options) {
  if (options.width < 160 || options.width > 1920) {
    return absl::InvalidArgumentError(
        absl::StrCat("StackedPileOptions.width must be in [160, 1920], got ",
                     options.width));
  }
  if (options.height < 120 || options.height > 1080) {
    return absl::InvalidArgumentError(
        absl::StrCat("StackedPileOptions.height must be in [120, 1080], got ",
                     options.height));
  }
  return absl::OkStatus();
}

StackedPileOptions SensorPileOptions(RoomSensor sensor) {
  StackedPileOptions options;
  const cv::Size size = SensorFrameSize(sensor);
  options.width = size.width;
  options.height = size.height;
  return options;
}

StackedPileOptions AbovePileOptions(RoomSensor sensor) {
  StackedPileOptions options = SensorPileOptions(sensor);
  options.more_kinds = true;
  options.from_above = true;
  if (sensor == RoomSensor::kActiveStereo) {
    options.width = 1280;
    options.height = 720;
  }
  return options;
}

}  // namespace fovea::synth
