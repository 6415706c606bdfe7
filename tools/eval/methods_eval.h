#ifndef FOVEA_TOOLS_EVAL_METHODS_EVAL_H_
#define FOVEA_TOOLS_EVAL_METHODS_EVAL_H_

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/segmentation_metrics.h"
#include "core/eval/uois_metrics.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/models.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/rbf_svm.h"
#include "core/segmentation/svm_training.h"
#include "tools/eval/scene_runner.h"

namespace fovea::eval {

// Whole-scene segmentation by several methods on the same labelled scenes,
// in one run, each scored by the thesis's seeded protocol (section 3.2.4:
// F all / best / first, object recall, false masks), whole-scene F and the
// unseen-object metrics (UoisScore).
//
// Models: the shipped ones (`models`, as the server loads them): a
// held-out figure on scenes they were not trained on. With folds >= 2,
// cross-validation instead: scene i is in fold i mod folds and is scored
// with models trained on the other folds' scenes (for choosing parameters
// on training scenes; the output says so).
struct MethodsEvalOptions {
  std::vector<SceneMethod> methods;
  DetectOptions detect;
  const LoadedModels* models = nullptr;  // not owned; used when folds < 2
  int folds = 0;
  std::optional<bool> cover_scene;  // SceneRunOptions::cover_scene
  LinearSvmTrainingOptions cos_svm;
  RbfSvmTrainingOptions inc_svm;
  std::string out_dir;  // <scene>_<method>.png: masks beside the truth
  bool verbose = false;
};

struct MethodSceneResult {
  std::string name;
  std::string kind;
  SegmentationScore seeded;
  double whole_scene_f = 0.0;
  UoisScore uois;
  double first_ms = 0.0;
  double total_ms = 0.0;
};

struct MethodSummary {
  std::string method;
  std::string kind;  // "" = all scenes
  int scenes = 0;
  // Seeded protocol, as SegmentEvalSummary.
  double f_all = 0.0, f_best = 0.0, f_first = 0.0;
  double object_recall = 0.0, false_masks = 0.0;
  double whole_scene_f = 0.0;
  // Unseen-object metrics, means over scenes.
  double overlap_p = 0.0, overlap_r = 0.0, overlap_f = 0.0;
  double boundary_p = 0.0, boundary_r = 0.0, boundary_f = 0.0;
  double objects_075 = 0.0;
  double first_ms_median = 0.0, total_ms_median = 0.0;
};

using MethodResults = std::map<SceneMethod, std::vector<MethodSceneResult>>;

absl::StatusOr<MethodResults> EvaluateMethods(
    const std::vector<LabelledFrame>& scenes,
    const MethodsEvalOptions& options);

// Over the scenes of one kind ("" = all).
MethodSummary SummarizeMethod(SceneMethod method,
                              const std::vector<MethodSceneResult>& results,
                              const std::string& kind);

// Objects smaller than this are not counted (slivers seen through a gap),
// pixels of a 640x480 frame.
inline constexpr int kEvalMinObjectPixels = 50;

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_METHODS_EVAL_H_
