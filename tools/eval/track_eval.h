#ifndef FOVEA_TOOLS_EVAL_TRACK_EVAL_H_
#define FOVEA_TOOLS_EVAL_TRACK_EVAL_H_

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/models.h"
#include "core/synth/replayed_scene.h"
#include "core/synth/sequence.h"
#include "core/track/tracker.h"

namespace fovea::eval {

// One frame's identities: the ground-truth objects in view, the tracks
// reported with a mask, and the (truth id, track id) pairs whose masks
// overlap with IoU >= 0.5 (one-to-one by construction).
struct FrameIdentities {
  int truths = 0;
  int tracks = 0;
  std::vector<std::pair<int, int>> matched;
  // Each counted mask that matched no truth, for --verbose: "track <id>
  // <pixels> px, <share> on <truth id> (IoU <iou>)", the truth it lies on
  // most (0: none).
  std::vector<std::string> unmatched;
};

// The identity figures of one sequence (Ristani et al. 2016): the truth
// and track identities are paired one-to-one over the whole sequence so as
// to maximise the frames they are matched in (Kuhn-Munkres); IDTP is those
// frames, IDFN the truths' other detections, IDFP the tracks' others. A
// switch is a truth matched to another track than the last one it was
// matched to.
struct IdentityCounts {
  int64_t idtp = 0;
  int64_t idfp = 0;
  int64_t idfn = 0;
  int64_t switches = 0;
  int64_t truth_frames = 0;  // truth objects in view, summed over frames
};
IdentityCounts CountIdentities(const std::vector<FrameIdentities>& frames);
// 2 IDTP / (2 IDTP + IDFP + IDFN); 1 when there is nothing to count.
double Idf1(const IdentityCounts& counts);
IdentityCounts& operator+=(IdentityCounts& a, const IdentityCounts& b);

// A frame's identities from its tracked objects against the labels:
// truth objects with at least `min_pixels` labelled pixels count. A mask
// that matches a smaller truth object (a sliver of an occluded one) is
// ignored, as MOTChallenge ignores detections of ignored objects: it is
// neither a track found nor a false one.
FrameIdentities MatchFrame(const synth::SequenceFrame& frame,
                           const std::vector<TrackedObject>& objects,
                           int min_pixels = 200);

// Mean over the frame's truth objects (at least `min_pixels`) of the best
// overlap F of any mask.
double MeanBestF(const synth::SequenceFrame& frame,
                 const std::vector<cv::Mat>& masks, int min_pixels = 200);

// The truth masks of `now` (at least `min_pixels`) that appeared or moved
// (their centroid by more than 3 pixels: sensor noise and dropouts move it
// less; a 1 cm push at 1 m moves it 5), when some of them did and others
// did not (a camera that moved moves them all: none is returned).
std::vector<cv::Mat> ChangedTruths(const synth::SequenceFrame& before,
                                   const synth::SequenceFrame& now,
                                   int min_pixels = 200);
// Whether `mask` overlaps one of `truths` with IoU >= 0.5 (false when
// empty).
bool Covers(const cv::Mat& mask, const std::vector<cv::Mat>& truths);
// The tracker's whole time over the fresh calls' on the same frames (0
// when the fresh calls took none): what a stream costs, where the median
// frame's ratio says what a typical frame does.
double TotalCost(const std::vector<double>& track_ms,
                 const std::vector<double>& fresh_ms);

struct TrackFigures {
  std::string kind;
  int sequences = 0;
  int frames = 0;
  IdentityCounts identities;
  double overlap_f = 0.0;       // tracker, mean over frames
  double single_frame_f = 0.0;  // a fresh SegmentIncremental, same frames
  int64_t joined = 0;
  int64_t split = 0;  // parts of joined tracks that moved apart
  // Frame by frame, the masks matched to a truth (IoU >= 0.5) and the truths
  // plus masks: 2 matched / detections is the detection F1, what IDF1
  // would be were every identity kept (IDF1's bound given the masks).
  int64_t detections_matched = 0;
  int64_t detections = 0;
  double reused_fraction = 0.0;  // of the frames
  // Of the frames: those segmented only in the region that changed
  // (TrackedFrame::region).
  double region_fraction = 0.0;
  double median_track_ms = 0.0;
  double median_fresh_ms = 0.0;
  // Their sums' ratio: the stream's whole time against fresh calls' (the
  // median hides a few full cuts among many cheap frames, or the reverse).
  double total_cost = 0.0;
  // Frames of a still camera (the same pose as the frame before) where
  // some objects appeared or moved and others did not (ChangedTruths), and
  // of those, the frames whose first object segmented was one that
  // changed: the tracker's, and a fresh SegmentIncremental's.
  int change_frames = 0;
  int changed_first = 0;
  int fresh_changed_first = 0;
};

// 2 detections_matched / detections; 1 when there is nothing to count.
inline double DetectionF1(const TrackFigures& f) {
  return f.detections == 0 ? 1.0 : 2.0 * f.detections_matched / f.detections;
}

struct TrackEvalOptions {
  int count = 20;   // sequences per kind
  int frames = 12;  // per sequence
  uint64_t seed = 1;
  bool with_pose = true;  // send the camera's pose
  TrackerOptions tracker;
  // When set: the first out_sequences sequences of each kind, frame by
  // frame, as PNGs (colour | depth | the tracks' masks) in this folder.
  std::string out_dir;
  int out_sequences = 3;
  bool verbose = false;  // one line per sequence on stderr
};

// Plays `count` sequences, the s-th `sequence_at(s)`, through a Tracker
// with the shipped INC model, and each frame through a fresh
// RunSegmentIncremental too; the figures are named `kind`.
absl::StatusOr<TrackFigures> EvaluateSequences(
    const std::string& kind, int count,
    const std::function<synth::Sequence(int)>& sequence_at,
    const TrackEvalOptions& options, const LoadedModels& models);

// EvaluateSequences over options.count synthetic sequences of `kind`.
absl::StatusOr<TrackFigures> EvaluateTracking(synth::SequenceKind kind,
                                              const TrackEvalOptions& options,
                                              const LoadedModels& models);

// EvaluateSequences over options.count real scenes replayed as `kind`
// (synth::ReplayAsSequence), named "osd-<kind>": the s-th replays scene
// s % scenes.size() with seed options.seed + s. INVALID_ARGUMENT when
// `scenes` is empty.
absl::StatusOr<TrackFigures> EvaluateReplayedTracking(
    synth::ReplayKind kind, const std::vector<LabelledFrame>& scenes,
    const TrackEvalOptions& options, const LoadedModels& models);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_TRACK_EVAL_H_
