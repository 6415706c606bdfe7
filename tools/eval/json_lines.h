#ifndef FOVEA_TOOLS_EVAL_JSON_LINES_H_
#define FOVEA_TOOLS_EVAL_JSON_LINES_H_

#include <string>

#include "tools/eval/detect_eval.h"
#include "tools/eval/inc_eval.h"
#include "tools/eval/methods_eval.h"
#include "tools/eval/raw_frame_eval.h"
#include "tools/eval/room_eval.h"

namespace fovea::eval {

// The lines `fovea-eval ... --json` prints: one JSON object each, compact
// (no spaces, no newline), its keys in the order below. Written by
// nlohmann::json, so every line parses as JSON whatever the values are:
//   - a number that is not finite (NaN, +-infinity: e.g. a mean or median
//     over nothing) is written as null, since JSON has no NaN or Infinity;
//   - a number is rounded as its text table column (or the line before the
//     JSON library) rounded it: the decimals each function names;
//   - a string (a method, group or scene name) is escaped; bytes that are
//     not UTF-8 become U+FFFD.

// `detect`: scenes, hit_ratio (the first max(K, 10) points),
// hit_ratio_all_points, distance_to_center,
// distance_to_center_thesis, hit_ratio_at (HR(N) for N = 1..10),
// scenes_10plus, hit_ratio_10plus (of `many`: the scenes of 10 or more
// objects), repeated_points, off_object_points, detect_ms_median. Numbers
// to six significant digits.
std::string DetectSummaryJson(const DetectEvalSummary& summary,
                              const DetectEvalSummary& many);

// `segment --method inc --inc_saliency random-points`: scenes, f_all,
// f_best, f_first, object_recall, false_masks, whole_scene_f; 4 decimals.
std::string IncSummaryJson(const IncEvalSummary& summary);

// `segment`, one line per method: method, evaluation ("cross-validated" or
// "held-out"), folds (0 when held out), scenes, f_all, f_best, f_first,
// object_recall, false_masks, whole_scene_f, overlap_p, overlap_r,
// overlap_f, boundary_p, boundary_r, boundary_f, objects_075 (4 decimals),
// first_mask_ms_median, all_masks_ms_median (1 decimal).
std::string MethodSummaryJson(const MethodSummary& summary,
                              bool cross_validated, int folds);

// `rooms`, one line per group and one for all ("all" when summary.group is
// empty): group, rooms, support_correct, object_recall,
// false_objects_per_frame, overlap_p, overlap_r, overlap_f, boundary_f,
// objects_075, whole_scene_f (4 decimals), first_ms_median,
// total_ms_median (1 decimal).
std::string RoomSummaryJson(const RoomSummary& summary);

// `raw`, one line per scene and frame ("cropped" or "raw"): scene, frame,
// masks, precision, recall (4 decimals), false_objects, overlap_f (4
// decimals).
std::string RawFrameJson(const std::string& scene, const std::string& frame,
                         const RawFrameScore& score);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_JSON_LINES_H_
