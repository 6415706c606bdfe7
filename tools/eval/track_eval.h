#ifndef FOVEA_TOOLS_EVAL_TRACK_EVAL_H_
#define FOVEA_TOOLS_EVAL_TRACK_EVAL_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/pipeline/models.h"
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
// truth objects with at least `min_pixels` labelled pixels count.
FrameIdentities MatchFrame(const synth::SequenceFrame& frame,
                           const std::vector<TrackedObject>& objects,
                           int min_pixels = 200);

// Mean over the frame's truth objects (at least `min_pixels`) of the best
// overlap F of any mask.
double MeanBestF(const synth::SequenceFrame& frame,
                 const std::vector<cv::Mat>& masks, int min_pixels = 200);

struct TrackFigures {
  std::string kind;
  int sequences = 0;
  int frames = 0;
  IdentityCounts identities;
  double overlap_f = 0.0;       // tracker, mean over frames
  double single_frame_f = 0.0;  // a fresh SegmentIncremental, same frames
  int64_t joined = 0;
  double reused_fraction = 0.0;  // of the frames
  double median_track_ms = 0.0;
  double median_fresh_ms = 0.0;
};

struct TrackEvalOptions {
  int count = 20;   // sequences per kind
  int frames = 12;  // per sequence
  uint64_t seed = 1;
  bool with_pose = true;  // send the camera's pose
  TrackerOptions tracker;
};

// Plays `count` sequences of `kind` through a Tracker with the shipped INC
// model, and each frame through a fresh RunSegmentIncremental too.
absl::StatusOr<TrackFigures> EvaluateTracking(synth::SequenceKind kind,
                                              const TrackEvalOptions& options,
                                              const LoadedModels& models);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_TRACK_EVAL_H_
