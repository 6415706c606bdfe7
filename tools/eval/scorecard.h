#ifndef FOVEA_TOOLS_EVAL_SCORECARD_H_
#define FOVEA_TOOLS_EVAL_SCORECARD_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/uois_metrics.h"
#include "core/pipeline/models.h"
#include "tools/eval/realism_eval.h"
#include "tools/eval/scene_runner.h"

namespace fovea::eval {

// One scorecard over every kind of scene Fovea is measured on, so that no
// change can lower one kind's figures unseen (`fovea-eval scorecard`,
// docs/scorecard.md). Sets:
//   osd          the OSD learn scenes, leave-one-kind-out: each kind
//                (boxes, stacked, occluded, cylindric) scored with models
//                trained on the other three kinds (and the synthetic
//                training piles the shipped INC model also uses), so every
//                figure is on a kind the models did not see;
//   osd-rot90, osd-rot180, osd-half
//                the same scenes rolled a quarter and a half turn, and at
//                half resolution (core/frame/frame_transform.h), scored
//                with the same fold models;
//   piles        synthetic piles (core/synth GeneratePile, seeds from 1:
//                the shipped model trained on seeds from 1000001);
//   stacked      synthetic stacked piles (boxes on books and boxes, cups in
//                bowls, objects in a box, mugs with handles), Kinect and
//                active-stereo noise;
//   stacked-above  stacked piles with every kind (drills, bananas, pens,
//                small parts, towers) seen from above, the Kinect at
//                640x480 and active stereo at 1280x720;
//   rooms        synthetic rooms, Kinect and active stereo;
//   realsense    the four raw RealSense frames (marked pixels only).
// Everything but `osd*` uses the shipped models (held out).

struct ScorecardOptions {
  std::vector<SceneMethod> methods = {SceneMethod::kInc};
  std::string osd_dir;        // "" (or absent): the osd sets are skipped
  std::string realsense_dir;  // "" (or absent): skipped
  const LoadedModels* models = nullptr;  // shipped; not owned, required
  // Sets to run, by name as above ("stacked" and "rooms" cover both
  // sensors); empty: all.
  std::vector<std::string> sets;
  int piles = 40;    // scenes of `piles`
  int stacked = 30;  // scenes of `stacked`, per sensor
  int rooms = 30;    // rooms per sensor
  // Synthetic scenes added to each fold's INC training, as the shipped
  // model's (SyntheticTrainingScenes): piles, and stacked piles per sensor.
  int training_piles = 100;
  int training_stacked = 0;
  std::string out_dir;   // <set>/<scene>_<method>.png overlays
  bool verbose = false;  // one line per scene on stderr
};

// The figures of one set, method and kind (kind "all": the whole set).
// Means over scenes unless said otherwise.
struct ScorecardRow {
  std::string set, method, kind;
  std::string evaluation;  // "leave-one-kind-out" or "held-out"
  int scenes = 0;
  int objects = 0;  // pooled
  // Unseen-object metrics (core/eval/uois_metrics.h).
  double overlap_p = 0, overlap_r = 0, overlap_f = 0;
  double boundary_f = 0, objects_075 = 0;
  // Objects some segment matches with F >= 0.5, pooled.
  double object_recall = 0;
  // Segments lying mostly on an object, per object they lie on (1: every
  // object one mask; 2: in two pieces), pooled.
  double masks_per_object = 0;
  // Segments lying mostly on the table or on what is not an object, per
  // scene.
  double false_objects = 0;
  // Detect (server defaults): distinct objects hit among the first
  // max(K, 10) points / K (thesis section 2.6.1), and points on no object.
  double hit_ratio = 0, off_object_points = 0;
  // Scenes whose support search failed (NOT_FOUND): scored as empty.
  int no_support = 0;
  // RealSense only: marked table and off-table pixels a mask covers.
  int table_hits = 0;
  double total_ms_median = 0;
};

// One scene's segments against its labels (OSD convention: 0 no data, 1-9
// table and background, 10 k + j object k; objects under 50 pixels at
// 640x480, scaled with the pixel count, are background).
struct SegmentFigures {
  UoisScore uois;
  int objects = 0;  // ground-truth objects scored
  int found = 0;    // objects some segment matches with F >= 0.5
  // Segments whose labelled pixels lie mostly on one object (the object
  // with the most of them outnumbering the non-object pixels), and the
  // objects with at least one such segment: object_masks /
  // objects_with_masks is masks per object.
  int object_masks = 0, objects_with_masks = 0;
  // Segments whose labelled pixels lie mostly on no object.
  int false_objects = 0;
  // The objects no segment matches with F >= 0.5 (ObjectId), ascending.
  std::vector<int> missed;
  // (ObjectId, masks) of the objects that came out in more than one mask.
  std::vector<std::pair<int, int>> in_pieces;
};
// `segments`: CV_32SC1 of the labels' size, -1 none, else a segment id.
SegmentFigures ScoreSegments(const cv::Mat& labels, const cv::Mat& segments);

absl::StatusOr<std::vector<ScorecardRow>> RunScorecard(
    const ScorecardOptions& options);

// The rows as a Markdown table (docs/scorecard.md) and as one JSON
// document {"rows": [...]} (docs/scorecard.json), numbers to 4 decimals.
std::string ScorecardMarkdown(const std::vector<ScorecardRow>& rows);
std::string ScorecardJson(const std::vector<ScorecardRow>& rows);

// The realism rows (`fovea-eval realism`, docs/realism.md), one per
// comparison of a real set with a synthetic one: the mean and the largest
// KS distance over its statistics. The full scorecard runs them (set
// `realism`); the short form does not.
std::string RealismMarkdown(const std::vector<RealismComparison>& realism);
// ScorecardJson with a "realism" array beside "rows": sensor, real,
// synthetic, mean_ks, max_ks, worst.
std::string ScorecardJson(const std::vector<ScorecardRow>& rows,
                          const std::vector<RealismComparison>& realism);
// A realism row's mean KS may rise by at most this before it counts as a
// fall (the synthetic frames moved away from the real ones).
inline constexpr double kRealismMargin = 0.02;
// Every realism row whose mean KS rose beyond kRealismMargin above the
// baseline's row of the same real and synthetic sets, one line each; rows
// absent from either side, or a baseline without "realism", are not
// compared. INVALID_ARGUMENT when the baseline does not parse.
absl::StatusOr<std::vector<std::string>> CompareRealismRows(
    const std::vector<RealismComparison>& realism,
    const std::string& baseline_json);

// Margins of CompareScorecard: how far a figure may move the wrong way
// before it counts as a fall. F, ratios and recalls may fall by at most
// kScoreMargin; masks per object and false objects per scene may rise by
// at most kCountMargin.
inline constexpr double kScoreMargin = 0.01;
inline constexpr double kCountMargin = 0.05;

// Every figure of `rows` that fell beyond its margin below the row of the
// same set, method and kind in `baseline_json` (ScorecardJson's format),
// one line each ("osd/inc/stacked overlap_f 0.9412 -> 0.9120 (baseline
// 0.9412, margin 0.01)"); rows absent from either side are not compared.
// INVALID_ARGUMENT when the baseline does not parse.
absl::StatusOr<std::vector<std::string>> CompareScorecard(
    const std::vector<ScorecardRow>& rows, const std::string& baseline_json);

// `fovea-eval scorecard` (its flags in scorecard_command.cc): 0, 1 on an
// error, 3 when --baseline is given and a figure fell beyond its margin.
int RunScorecardCommand();

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SCORECARD_H_
