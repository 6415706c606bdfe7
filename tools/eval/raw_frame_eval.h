#ifndef FOVEA_TOOLS_EVAL_RAW_FRAME_EVAL_H_
#define FOVEA_TOOLS_EVAL_RAW_FRAME_EVAL_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/uois_metrics.h"
#include "tools/eval/scene_runner.h"

namespace fovea::eval {

// OSD's scenes were cropped (floor, walls and the table's far end removed);
// the raw sensor frames they came from show the whole room. For each raw
// frame `frames/<scene>_color.png` + `_depth_mm.png` of an OSD folder with
// its labelled `learn/<scene>.pcd` (pixel-aligned: the crop only removed
// points), the same method runs on the cropped and on the raw frame, and
// both are scored against the scene's labels (outside the crop nothing is
// an object, so a mask there lowers precision).
struct RawFrameScore {
  double precision = 0.0;  // mask pixels on an object / mask pixels
  double recall = 0.0;     // object pixels in a mask / object pixels
  int masks = 0;
  int false_objects = 0;  // masks mostly off the objects
  UoisScore uois;
  double total_ms = 0.0;
};

struct RawFrameResult {
  std::string name;
  RawFrameScore cropped;
  RawFrameScore raw;
};

// Errors: NOT_FOUND when the folder has no raw frame with a labelled
// scene; what the method returns.
absl::StatusOr<std::vector<RawFrameResult>> EvaluateRawFrames(
    const std::string& osd_dir, const SceneRunOptions& options);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_RAW_FRAME_EVAL_H_
