#ifndef FOVEA_TOOLS_EVAL_SCENE_RUNNER_H_
#define FOVEA_TOOLS_EVAL_SCENE_RUNNER_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/name_table.h"
#include "core/eval/segmentation_metrics.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/segment.h"
#include "core/scene/support_plane.h"

namespace fovea::eval {

// One whole-scene segmentation of a labelled frame by a method as the
// server runs it (models as loaded, no retraining): what the held-out
// evaluations (rooms, piles, any folder) score.
enum class SceneMethod { kInc, kCos, kEbs, kPclLccp, kPclEuclidean };

// "inc", "cos", "ebs", "pcl-lccp", "pcl-euclidean" (core/base/name_table.h).
absl::Span<const NamedValue<SceneMethod>> SceneMethods();
std::string_view SceneMethodName(SceneMethod method);
absl::StatusOr<SceneMethod> ParseSceneMethod(std::string_view text);

struct SceneRunOptions {
  SceneMethod method = SceneMethod::kInc;
  DetectOptions detect;  // seeds / saliency, scene (sensor, hints)
  SegmentModels models;  // not owned; those the method needs
  // COS / EBS: SegmentOptions::cover_scene (unset: on, as for all objects).
  std::optional<bool> cover_scene;
};

struct SceneRun {
  std::vector<SeededMask> masks;  // in the order they came, frame's size
  // COS / EBS / INC: the attention points Detect gave the run (its seeds,
  // or INC's order), most salient first, in the frame's pixels.
  std::vector<AttentionPoint> points;
  cv::Mat segments;  // CV_32SC1: mask index, -1 none
  // The support the scene was prepared on (the peers: none).
  std::optional<SupportPlane> support;
  double first_ms = 0.0;  // to the first object (the whole run if none)
  double total_ms = 0.0;  // the whole run
};

// The colour (BGR) overlays tint the i-th mask with.
inline cv::Scalar MaskColor(size_t i) {
  return cv::Scalar(static_cast<double>((i * 67) % 256),
                    static_cast<double>((80 + i * 151) % 256),
                    static_cast<double>((160 + i * 97) % 256));
}

// Runs `options.method` on the frame to the end (every seed, the whole
// scene). Where masks overlap (COS and EBS may), the earlier keeps the
// pixel in `segments`.
absl::StatusOr<SceneRun> RunOnScene(const LabelledFrame& scene,
                                    const SceneRunOptions& options);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SCENE_RUNNER_H_
