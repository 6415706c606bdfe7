#ifndef FOVEA_TOOLS_EVAL_INC_EVAL_H_
#define FOVEA_TOOLS_EVAL_INC_EVAL_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/segmentation_metrics.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/incremental.h"
#include "core/segmentation/svm_training.h"

namespace fovea::eval {

// INC on labelled scenes by section 3.3.3's protocols, cross-validated
// (scene i in fold i mod folds, scored by the SVM trained on the others).
enum class IncSaliency {
  kSym3d,         // Detect's default map; F from the objects of one run
  kRandomPoints,  // per object, 5 sequences of 5 points (first on it)
};

struct IncEvalOptions {
  IncrementalOptions incremental;
  IncSaliency saliency = IncSaliency::kSym3d;
  int folds = 5;
  RbfSvmTrainingOptions svm;
  int sequences_per_object = 5;  // thesis: 5
  int points_per_sequence = 5;   // thesis: 5
  std::string out_dir;  // complexity.csv, complexity.png, <scene>_inc.png
  bool verbose = false;
};

struct IncSceneResult {
  std::string name;
  std::string kind;
  SegmentationScore score;  // first / best / all, recall, false masks
  double whole_scene_f = 0.0;
  double first_object_ms = 0.0;  // SYM3D run to the end: first object
  double whole_scene_ms = 0.0;   // ... and the whole scene
  int objects_emitted = 0;
};

struct IncEvalSummary {
  std::vector<IncSceneResult> scenes;
  double f_all = 0.0, f_best = 0.0, f_first = 0.0;
  double object_recall = 0.0, false_masks = 0.0;
  double whole_scene_f = 0.0;
  double first_object_ms_median = 0.0;
  double whole_scene_ms_median = 0.0;
  // Least-squares slope of the time to the first object against the time
  // of the whole scene (complexity), ms per ms.
  double first_object_slope = 0.0;
};

absl::StatusOr<IncEvalSummary> EvaluateInc(
    const std::vector<LabelledFrame>& scenes, const IncEvalOptions& options);

// Means and medians over the scenes of one kind ("" = all).
IncEvalSummary SummarizeInc(const std::vector<IncSceneResult>& scenes,
                            const std::string& kind);

// complexity.csv and complexity.png (Fig. 3.13: times against scene
// complexity, scenes ordered by whole-scene time) into `dir`.
absl::Status WriteComplexity(const std::vector<IncSceneResult>& scenes,
                             const std::string& dir);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_INC_EVAL_H_
