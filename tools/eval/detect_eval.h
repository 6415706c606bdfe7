#ifndef FOVEA_TOOLS_EVAL_DETECT_EVAL_H_
#define FOVEA_TOOLS_EVAL_DETECT_EVAL_H_

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/baseline/pcl_clusters.h"
#include "core/eval/detection_metrics.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/detect.h"

namespace fovea::eval {

struct SceneResult {
  std::string name;
  std::string kind;                   // SceneKind(name)
  DetectionScore score;               // HR over the first max(K, 10) points
  double hit_ratio_all_points = 0.0;  // HR over every point returned
  int points = 0;
  double detect_ms = 0.0;
};

struct DetectEvalSummary {
  std::vector<SceneResult> scenes;  // scenes with at least one object
  // Mean over scenes of the thesis's HR: distinct objects hit among the
  // first max(K, 10) points / K (section 2.6.1), however many points
  // Detect returned; and of HR over every point returned (an extraction
  // that returns a point per region hits more the more it returns: read
  // it with off_object_points).
  double hit_ratio = 0.0;
  double hit_ratio_all_points = 0.0;
  double distance_to_center = 0.0;  // mean over scenes
  double distance_to_center_thesis = 0.0;
  std::array<double, kHitRatioAtMax> hit_ratio_at{};
  // Means per scene: points on an object an earlier point hit, points on
  // no object (DetectionScore).
  double repeated_points = 0.0;
  double off_object_points = 0.0;
  double detect_ms_median = 0.0;
};

struct DetectEvalOptions {
  std::string data_dir;  // an OSD folder (or its learn/ subfolder)
  DetectOptions detect;
  // Run the pcl-clusters peer instead of the attention system (uses the
  // support plane and table scene options of `detect` only).
  bool pcl_clusters = false;
  PclClustersOptions clusters;
  std::string out_dir;   // when set, PNGs of maps and points per scene
  bool verbose = false;  // one line per scene on stderr
};

// Runs Detect in-process on every PCD of the folder and scores it
// (thesis section 2.6.1; objects are label / 10).
absl::StatusOr<DetectEvalSummary> EvaluateDetect(
    const DetectEvalOptions& options);

// The PCDs of an OSD folder (or its learn/ subfolder), loaded once.
absl::StatusOr<std::vector<LabelledFrame>> LoadScenes(
    const std::string& data_dir);

// EvaluateDetect on scenes already loaded (options.data_dir is ignored).
absl::StatusOr<DetectEvalSummary> EvaluateDetectOn(
    const std::vector<LabelledFrame>& scenes, const DetectEvalOptions& options);

// Mean of the per-scene figures over the scenes of one kind ("" = all).
DetectEvalSummary Summarize(const std::vector<SceneResult>& scenes,
                            const std::string& kind);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_DETECT_EVAL_H_
