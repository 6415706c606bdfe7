#ifndef FOVEA_TOOLS_EVAL_REPLAY_H_
#define FOVEA_TOOLS_EVAL_REPLAY_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace fovea::eval {

// fovea-eval replay DIR --server HOST:PORT: each call the flight recorder
// kept in DIR (server/flight_recorder.h) sent again, and what changed.

struct ReplayOptions {
  std::string server;        // a FoveaClient target
  double deadline_s = 60.0;  // per call
  // Two attention points are the same point within this, pixels; two
  // masks the same object at this IoU or more.
  double point_match_px = 20.0;
  double same_object_iou = 0.5;
  // A record changed when a point moved more than this (pixels), a
  // matched mask's IoU fell below this, an object or point was found or
  // lost, or the status code differs.
  double changed_point_px = 2.0;
  double changed_iou = 0.9;
};

// What one record's replay gave.
struct ReplayResult {
  std::string record;  // the folder's name, "00000012-Detect"
  std::string method;
  std::string recorded_code, code;  // gRPC status code names
  std::string error;  // why it could not be replayed (then skipped)
  // Detect: attention points; Segment / SegmentIncremental: objects;
  // Track: objects in view, over all its frames.
  int recorded = 0, now = 0;
  int matched = 0, lost = 0, found = 0;
  double mean_shift_px = 0.0, max_shift_px = 0.0;  // Detect's points
  double mean_iou = 1.0, min_iou = 1.0;            // matched masks
  double recorded_ms = 0.0, now_ms = 0.0;          // server time / round trip
  // Track: the frames recorded and answered now (objects above are summed
  // over them), and recorded tracks whose matched object changed id.
  int frames = 0, frames_now = 0, id_switches = 0;
  bool changed = false;
};

// Replays every record of `dir` in sequence order. Errors: the folder
// cannot be read, the server target is invalid. A record that cannot be
// read or whose call fails is a result with `error` (or `code`) set.
absl::StatusOr<std::vector<ReplayResult>> ReplayRecords(
    const std::string& dir, const ReplayOptions& options);

// fovea-eval replay: replays `dir`, prints a line per record and a summary
// (a JSON line per record and one for the summary with `json`). Exit code:
// 0; 1 when a record could not be replayed or its call failed where the
// recorded one had not; 2 for a usage error (no folder, no server); 3,
// with `fail_on_change`, when any record changed.
int RunReplay(const std::string& dir, const ReplayOptions& options, bool json,
              bool fail_on_change);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_REPLAY_H_
