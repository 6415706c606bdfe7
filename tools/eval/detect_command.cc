// fovea-eval detect, and the Detect options of the flags every command shares.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/models.h"
#include "core/segmentation/svm_training.h"
#include "core/synth/synth_scene.h"
#ifdef FOVEA_EVAL_REPLAY
#include "tools/eval/replay.h"
#endif
#include "absl/flags/declare.h"
#include "tools/eval/commands.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/inc_eval.h"
#include "tools/eval/json_lines.h"
#include "tools/eval/methods_eval.h"
#include "tools/eval/raw_frame_eval.h"
#include "tools/eval/room_eval.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/scorecard.h"
#include "tools/eval/sweep.h"

ABSL_DECLARE_FLAG(std::string, combine);
ABSL_DECLARE_FLAG(double, edge_concave);
ABSL_DECLARE_FLAG(double, edge_concave_sharpness);
ABSL_DECLARE_FLAG(double, edge_jump);
ABSL_DECLARE_FLAG(int, edge_radius);
ABSL_DECLARE_FLAG(std::string, extract);
ABSL_DECLARE_FLAG(bool, fill_holes);
ABSL_DECLARE_FLAG(std::string, fusion);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(bool, msr_inhibit_slope);
ABSL_DECLARE_FLAG(std::string, norm);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(int, points);
ABSL_DECLARE_FLAG(int, processing_width);
ABSL_DECLARE_FLAG(std::string, pyramid);
ABSL_DECLARE_FLAG(std::string, saliency);
ABSL_DECLARE_FLAG(std::string, sensor);
ABSL_DECLARE_FLAG(bool, split_edges);
ABSL_DECLARE_FLAG(int, sym3d_kernel);
ABSL_DECLARE_FLAG(int, sym3d_level);
ABSL_DECLARE_FLAG(std::string, tj_junction);
ABSL_DECLARE_FLAG(std::string, tj_rank);
ABSL_DECLARE_FLAG(double, tj_support);
ABSL_DECLARE_FLAG(bool, verbose);

namespace fovea::eval {
namespace {

// Scenes of `scenes` with at least `objects` objects.
std::vector<SceneResult> WithObjects(const std::vector<SceneResult>& scenes,
                                     int objects) {
  std::vector<SceneResult> out;
  for (const SceneResult& r : scenes) {
    if (r.score.objects >= objects) out.push_back(r);
  }
  return out;
}

// Scenes with at least this many objects get a row of their own: what a
// detector capped at ten points could never cover.
constexpr int kManyObjects = 10;

void PrintTable(const std::vector<SceneResult>& scenes) {
  std::printf("%-12s %7s %7s %7s %7s %11s %9s %9s %9s\n", "kind", "scenes",
              "HR", "HR(all)", "DC", "DC(thesis)", "repeats", "off", "ms(med)");
  std::vector<std::string> kinds;
  for (const SceneResult& r : scenes) {
    if (std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) {
      kinds.push_back(r.kind);
    }
  }
  kinds.push_back("");
  auto row = [](const std::string& name, const DetectEvalSummary& s) {
    std::printf("%-12s %7zu %7.3f %7.3f %7.3f %11.3f %9.2f %9.2f %9.1f\n",
                name.c_str(), s.scenes.size(), s.hit_ratio,
                s.hit_ratio_all_points, s.distance_to_center,
                s.distance_to_center_thesis, s.repeated_points,
                s.off_object_points, s.detect_ms_median);
  };
  for (const std::string& kind : kinds) {
    const DetectEvalSummary s = Summarize(scenes, kind);
    if (!s.scenes.empty()) row(kind.empty() ? "all" : kind, s);
  }
  const std::vector<SceneResult> many = WithObjects(scenes, kManyObjects);
  if (!many.empty())
    row(absl::StrCat(kManyObjects, "+ objects"), Summarize(many, ""));
}

// The detect --json line; its 10plus keys are of the kManyObjects row.
std::string Json(const DetectEvalSummary& s) {
  static_assert(kManyObjects == 10, "the JSON keys say 10plus");
  return DetectSummaryJson(s,
                           Summarize(WithObjects(s.scenes, kManyObjects), ""));
}

}  // namespace

// The Detect options of the flags shared by detect and segment; nullopt
// (after a message on stderr) when one does not parse.
std::optional<DetectOptions> DetectOptionsFromFlags() {
  DetectOptions detect;
  const std::string saliency = absl::GetFlag(FLAGS_saliency);
  absl::StatusOr<std::vector<SaliencyOp>> ops =
      ParseSaliencyOps(saliency == "pcl-clusters" ? "rso" : saliency);
  if (!ops.ok()) {
    std::fprintf(stderr, "fovea-eval: --%s\n", ops.status().ToString().c_str());
    return std::nullopt;
  }
  absl::StatusOr<ExtractionKind> extract =
      ParseExtraction(absl::GetFlag(FLAGS_extract));
  if (!extract.ok()) {
    std::fprintf(stderr, "fovea-eval: --%s\n",
                 extract.status().ToString().c_str());
    return std::nullopt;
  }
  detect.channels.clear();
  for (SaliencyOp op : *ops) detect.channels.push_back({op, 1.0f});
  detect.extraction = *extract;
  detect.max_points = absl::GetFlag(FLAGS_points);
  detect.msr.inhibit_slope = absl::GetFlag(FLAGS_msr_inhibit_slope);
  detect.fill_holes = absl::GetFlag(FLAGS_fill_holes);
  detect.sym3d_level = absl::GetFlag(FLAGS_sym3d_level);
  detect.sym3d.kernel_size = absl::GetFlag(FLAGS_sym3d_kernel);
  detect.tj.support_fraction =
      static_cast<float>(absl::GetFlag(FLAGS_tj_support));
  const std::string tj_junction = absl::GetFlag(FLAGS_tj_junction);
  const std::string tj_rank = absl::GetFlag(FLAGS_tj_rank);
  if ((tj_junction != "central" && tj_junction != "salient") ||
      (tj_rank != "total" && tj_rank != "mean")) {
    std::fprintf(stderr,
                 "fovea-eval: --tj_junction central|salient, "
                 "--tj_rank total|mean\n");
    return std::nullopt;
  }
  detect.tj.junction = tj_junction == "central" ? TjJunction::kCentral
                                                : TjJunction::kMostSalient;
  detect.tj.ranking =
      tj_rank == "total" ? TjRanking::kTotalSaliency : TjRanking::kMeanSaliency;
  detect.split_at_surface_edges = absl::GetFlag(FLAGS_split_edges);
  detect.surface_edges.depth_jump_fraction =
      static_cast<float>(absl::GetFlag(FLAGS_edge_jump));
  detect.surface_edges.concave_curvature =
      static_cast<float>(absl::GetFlag(FLAGS_edge_concave));
  detect.surface_edges.concave_min_curvature =
      static_cast<float>(absl::GetFlag(FLAGS_edge_concave_sharpness));
  detect.surface_edges.radius_px = absl::GetFlag(FLAGS_edge_radius);
  const absl::StatusOr<PyramidKind> pyramid =
      ParsePyramid(absl::GetFlag(FLAGS_pyramid));
  const absl::StatusOr<LevelCombination> combine =
      ParseLevelCombination(absl::GetFlag(FLAGS_combine));
  const absl::StatusOr<NormalizationKind> norm =
      ParseNormalization(absl::GetFlag(FLAGS_norm));
  const absl::StatusOr<FusionKind> fusion =
      ParseFusion(absl::GetFlag(FLAGS_fusion));
  if (!pyramid.ok() || !combine.ok() || !norm.ok() || !fusion.ok()) {
    std::fprintf(stderr,
                 "fovea-eval: --pyramid none|simple|itti, --combine sum|max, "
                 "--norm lin|nms|nlm, --fusion sum|max\n");
    return std::nullopt;
  }
  const absl::StatusOr<SensorKind> sensor =
      ParseSensorKind(absl::GetFlag(FLAGS_sensor));
  if (!sensor.ok()) {
    std::fprintf(stderr, "fovea-eval: --%s\n",
                 sensor.status().ToString().c_str());
    return std::nullopt;
  }
  detect.scene.sensor = *sensor;
  detect.scene.processing_width = absl::GetFlag(FLAGS_processing_width);
  detect.pyramid = *pyramid;
  detect.level_combination = *combine;
  detect.normalization = *norm;
  detect.fusion = *fusion;
  return detect;
}

std::optional<std::vector<LabelledFrame>> ScenesFromFlags();

int RunDetectEval() {
  DetectEvalOptions options;
  const std::string saliency = absl::GetFlag(FLAGS_saliency);
  options.pcl_clusters = saliency == "pcl-clusters";
  std::optional<DetectOptions> detect = DetectOptionsFromFlags();
  if (!detect) return kUsageError;
  options.detect = *std::move(detect);
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);

  const std::optional<std::vector<LabelledFrame>> scenes = ScenesFromFlags();
  if (!scenes) return kRunError;
  absl::StatusOr<DetectEvalSummary> summary =
      EvaluateDetectOn(*scenes, options);
  if (!summary.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 summary.status().ToString().c_str());
    return kRunError;
  }
  std::printf("saliency %s, extraction %s, %zu scenes\n",
              absl::GetFlag(FLAGS_saliency).c_str(),
              absl::GetFlag(FLAGS_extract).c_str(), summary->scenes.size());
  PrintTable(summary->scenes);
  if (absl::GetFlag(FLAGS_json)) std::printf("%s\n", Json(*summary).c_str());
  return 0;
}

}  // namespace fovea::eval
