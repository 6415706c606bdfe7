#ifndef FOVEA_TOOLS_EVAL_REALISM_EVAL_H_
#define FOVEA_TOOLS_EVAL_REALISM_EVAL_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/realism.h"
#include "core/frame/osd_pcd.h"

namespace fovea::eval {

// `fovea-eval realism` (docs/realism.md): the synthetic scenes of each
// sensor family against that sensor's real frames, statistic by statistic
// (core/eval/realism.h), every frame seen as Fovea sees it (PrepareScene
// with the segmentations' default options, measured depth only, as the
// relation SVM's training examples are taken).
//
// Real sets: `osd` (the OSD learn scenes, Kinect v1, cropped, labelled) and
// `realsense` (the four raw frames, active stereo, unlabelled). Synthetic
// sets, rendered with the matching sensor model, resolution (640 x 480) and
// view: `random` (GenerateScene: 2-6 objects, the demo's), `piles`
// (GeneratePile, the INC model's training piles' generator), `stacked`
// (GenerateStackedPile) for the Kinect; `rooms` (GenerateRoom) and
// `stacked` for active stereo. Seeds from 1.

struct RealismEvalOptions {
  std::string osd_dir;        // "": the osd comparisons are skipped
  std::string realsense_dir;  // "": the realsense ones are skipped
  int synthetic = 20;         // scenes per synthetic set, > 0
  bool verbose = false;       // one line per frame on stderr
};

// Median depth noise (the plane cells' residual sigma, m) in one range of
// depths, real and synthetic.
struct NoiseAtRange {
  double min_z = 0.0, max_z = 0.0;  // m
  int real_cells = 0, synthetic_cells = 0;
  double real_sigma = 0.0, synthetic_sigma = 0.0;  // m; NaN without cells
};

struct RealismComparison {
  std::string sensor;           // "kinect_v1", "active_stereo"
  std::string real, synthetic;  // set names
  int real_frames = 0, synthetic_frames = 0;
  std::vector<RealismDistance> rows;  // CompareRealism's
  std::vector<NoiseAtRange> noise;
};

// Every comparison whose real set is at hand; INVALID_ARGUMENT for
// synthetic <= 0, a real set's load error.
absl::StatusOr<std::vector<RealismComparison>> RunRealism(
    const RealismEvalOptions& options);

// The samples of one frame as RunRealism takes them: CollectRealismSamples
// on the prepared scene, with INC's relation examples and patches per
// object when `labels` is non-empty. Exposed for the tests.
absl::StatusOr<RealismSet> RealismOfFrames(
    const std::string& name, const std::vector<LabelledFrame>& frames,
    bool verbose);

// Text: per comparison, the summary (mean and largest KS over the frame,
// object and relation statistics), the noise against range and every
// statistic. JSON: one document {"comparisons": [...]}, numbers to 4
// significant decimals, NaN as null.
std::string RealismText(const std::vector<RealismComparison>& comparisons);
std::string RealismJson(const std::vector<RealismComparison>& comparisons);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_REALISM_EVAL_H_
