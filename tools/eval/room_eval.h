#ifndef FOVEA_TOOLS_EVAL_ROOM_EVAL_H_
#define FOVEA_TOOLS_EVAL_ROOM_EVAL_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/uois_metrics.h"
#include "core/synth/room.h"
#include "tools/eval/scene_runner.h"

namespace fovea::eval {

// Synthetic rooms (core/synth/room.h) segmented as the server would, held
// out: nothing is trained on them. Per room: whether the support found is
// the support table, how many of its objects were found, how many masks lie
// on something else, and the unseen-object metrics.

struct RoomEvalOptions {
  int count = 200;    // rooms per configuration
  uint64_t seed = 1;  // room seeds are seed, seed + 1, ...
  // The configurations: each sensor at each resolution.
  std::vector<synth::RoomSensor> sensors = {synth::RoomSensor::kKinectV1,
                                            synth::RoomSensor::kActiveStereo};
  std::vector<cv::Size> sizes = {{640, 480}};
  synth::RoomOptions room;  // sensor and size are set per configuration
  SceneRunOptions run;
  std::string out_dir;  // <room>.png: masks, support and ground truth
  bool verbose = false;
};

struct RoomResult {
  std::string name;
  std::string group;  // "kinect_v1 640x480", ...
  bool support_correct = false;
  int objects = 0;        // on the support table, large enough to count
  int objects_found = 0;  // matched by a mask with F >= 0.5
  int false_objects = 0;  // masks lying mostly on something else
  int masks = 0;
  UoisScore uois;
  double whole_scene_f = 0.0;
  double first_ms = 0.0;
  double total_ms = 0.0;
};

struct RoomSummary {
  std::string group;  // "" = all
  int rooms = 0;
  double support_correct = 0.0;  // share of rooms
  double object_recall = 0.0;    // pooled over rooms
  double false_objects_per_frame = 0.0;
  double overlap_p = 0.0, overlap_r = 0.0, overlap_f = 0.0;  // means
  double boundary_f = 0.0, objects_075 = 0.0, whole_scene_f = 0.0;
  double first_ms_median = 0.0, total_ms_median = 0.0;
};

// Support correct: the chosen plane within 5 degrees and 2 cm of the
// support table's, and at least half its inlier pixels on that table (a
// second table at the same height is another surface). An object counts
// when it shows at least 50 pixels at 640x480 (scaled with the pixel
// count). A false object is a mask most of whose labelled pixels are not an
// object of the support table.
absl::StatusOr<std::vector<RoomResult>> EvaluateRooms(
    const RoomEvalOptions& options);

RoomSummary SummarizeRooms(const std::vector<RoomResult>& results,
                           const std::string& group);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_ROOM_EVAL_H_
