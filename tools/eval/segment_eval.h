#ifndef FOVEA_TOOLS_EVAL_SEGMENT_EVAL_H_
#define FOVEA_TOOLS_EVAL_SEGMENT_EVAL_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/eval/segmentation_metrics.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/segment.h"

namespace fovea::eval {

struct SegmentEvalOptions {
  // Method, seeds (options.detect.extraction) and method options; seeds
  // given in options.seeds are ignored.
  SegmentOptions segment;
  // Scene i is in fold i mod folds; each fold is scored with models
  // trained on the other folds, so no scene is scored by a model that saw
  // it.
  int folds = 5;
  LinearSvmTrainingOptions svm;
  std::string out_dir;   // when set, <scene>_masks.png per scene
  bool verbose = false;  // one line per scene on stderr
};

struct SceneSegmentResult {
  std::string name;
  std::string kind;  // SceneKind(name)
  SegmentationScore score;
  double whole_scene_f = 0.0;  // WholeSceneF of the masks (earlier first)
  double first_mask_ms = 0.0;  // request start to first object; 0 if none
  double all_masks_ms = 0.0;   // the whole RunSegment
};

struct SegmentEvalSummary {
  std::vector<SceneSegmentResult> scenes;
  // Table 3.1's F-scores: means over the scenes where some object got a
  // mask of the per-scene means over those objects.
  double f_all = 0.0;
  double f_best = 0.0;
  double f_first = 0.0;
  // Pooled over all scenes: objects with a mask seeded on them / objects;
  // masks seeded on the table or nothing / masks.
  double object_recall = 0.0;
  double false_masks = 0.0;
  double whole_scene_f = 0.0;  // mean over scenes
  double first_mask_ms_median = 0.0;
  double all_masks_ms_median = 0.0;
};

// Cross-validated segmentation quality on labelled scenes.
absl::StatusOr<SegmentEvalSummary> EvaluateSegment(
    const std::vector<LabelledFrame>& scenes,
    const SegmentEvalOptions& options);

// The summary over the scenes of one kind ("" = all).
SegmentEvalSummary SummarizeSegment(
    const std::vector<SceneSegmentResult>& scenes, const std::string& kind);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SEGMENT_EVAL_H_
