// fovea-eval segment: COS, EBS and INC on labelled scenes, cross-validated.

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

ABSL_DECLARE_FLAG(bool, cover_scene);
ABSL_DECLARE_FLAG(std::string, data);
ABSL_DECLARE_FLAG(int, folds);
ABSL_DECLARE_FLAG(std::string, inc_saliency);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(std::string, method);
ABSL_DECLARE_FLAG(std::string, models);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(int, piles);
ABSL_DECLARE_FLAG(uint64_t, seed);
ABSL_DECLARE_FLAG(std::string, seeds);
ABSL_DECLARE_FLAG(double, svm_c);
ABSL_DECLARE_FLAG(bool, verbose);

namespace fovea::eval {
namespace {

void PrintIncTable(const std::vector<IncSceneResult>& scenes) {
  std::printf("%-12s %7s %7s %7s %7s %8s %8s %8s %10s %10s\n", "kind", "scenes",
              "F(all)", "F(best)", "F(first)", "recall", "false", "wholeF",
              "first(ms)", "whole(ms)");
  for (const char* kind :
       {"boxes", "stacked", "occluded", "cylindric", "other", ""}) {
    const IncEvalSummary s = SummarizeInc(scenes, kind);
    if (s.scenes.empty()) continue;
    std::printf(
        "%-12s %7zu %7.3f %7.3f %7.3f %8.3f %8.3f %8.3f %10.1f %10.1f\n",
        kind[0] ? kind : "all", s.scenes.size(), s.f_all, s.f_best, s.f_first,
        s.object_recall, s.false_masks, s.whole_scene_f,
        s.first_object_ms_median, s.whole_scene_ms_median);
  }
}

// Section 3.3.3's random-points protocol (cross-validated INC).
int RunRandomPointsEval(const DetectOptions& detect,
                        const std::vector<LabelledFrame>& scenes) {
  IncEvalOptions options;
  options.incremental.detect = detect;
  options.saliency = IncSaliency::kRandomPoints;
  options.folds = std::max(2, absl::GetFlag(FLAGS_folds));
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);
  absl::StatusOr<IncEvalSummary> summary = EvaluateInc(scenes, options);
  if (!summary.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 summary.status().ToString().c_str());
    return kRunError;
  }
  std::printf(
      "segment inc, saliency random-points, %zu scenes, %d-fold "
      "cross-validated\n",
      summary->scenes.size(), options.folds);
  PrintIncTable(summary->scenes);
  if (absl::GetFlag(FLAGS_json)) {
    std::printf("%s\n", IncSummaryJson(*summary).c_str());
  }
  return 0;
}

}  // namespace

// commands.h
std::optional<std::vector<LabelledFrame>> ScenesFromFlags() {
  const int piles = absl::GetFlag(FLAGS_piles);
  if (piles > 0) {
    std::vector<LabelledFrame> scenes;
    for (int k = 0; k < piles; ++k) {
      scenes.push_back(
          synth::GeneratePile(absl::GetFlag(FLAGS_seed) + k).frame);
    }
    return scenes;
  }
  std::string data = absl::GetFlag(FLAGS_data);
  if (data.empty()) {
    const char* env = std::getenv("FOVEA_OSD_DIR");
    if (env != nullptr) data = env;
  }
  if (data.empty()) {
    std::fprintf(stderr,
                 "fovea-eval: --data (or FOVEA_OSD_DIR) or --piles is "
                 "required\n");
    return std::nullopt;
  }
  for (const std::string& kinds :
       {data + "/kinds.txt", data + "/learn/kinds.txt"}) {
    if (std::filesystem::exists(kinds)) {
      if (absl::Status s = LoadKinds(kinds); !s.ok()) {
        std::fprintf(stderr, "fovea-eval: %s\n", s.ToString().c_str());
        return std::nullopt;
      }
    }
  }
  absl::StatusOr<std::vector<LabelledFrame>> scenes = LoadScenes(data);
  if (!scenes.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 scenes.status().ToString().c_str());
    return std::nullopt;
  }
  return *std::move(scenes);
}

namespace {

// The kinds present among the results, in order of first appearance.
std::vector<std::string> KindsOf(const MethodResults& results) {
  std::vector<std::string> kinds;
  for (const auto& [method, scenes] : results) {
    for (const MethodSceneResult& r : scenes) {
      if (std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) {
        kinds.push_back(r.kind);
      }
    }
  }
  return kinds;
}

}  // namespace

int RunSegmentEval() {
  std::optional<DetectOptions> detect = DetectOptionsFromFlags();
  if (!detect) return kUsageError;
  const std::string seeds = absl::GetFlag(FLAGS_seeds);
  if (!seeds.empty()) {
    absl::StatusOr<ExtractionKind> kind = ParseExtraction(seeds);
    if (!kind.ok()) {
      std::fprintf(stderr, "fovea-eval: --seeds: %s\n",
                   kind.status().ToString().c_str());
      return kUsageError;
    }
    detect->extraction = *kind;
  }
  MethodsEvalOptions options;
  options.detect = *detect;
  std::string methods = absl::GetFlag(FLAGS_method);
  if (methods == "all") methods = "inc,cos,ebs,pcl-lccp,pcl-euclidean";
  for (absl::string_view name : absl::StrSplit(methods, ',')) {
    absl::StatusOr<SceneMethod> method = ParseSceneMethod(std::string(name));
    if (!method.ok()) {
      std::fprintf(stderr, "fovea-eval: --method: %s\n",
                   method.status().ToString().c_str());
      return kUsageError;
    }
    options.methods.push_back(*method);
  }
  const std::optional<std::vector<LabelledFrame>> scenes = ScenesFromFlags();
  if (!scenes) return kRunError;
  if (absl::GetFlag(FLAGS_inc_saliency) == "random-points") {
    return RunRandomPointsEval(options.detect, *scenes);
  }
  options.folds = absl::GetFlag(FLAGS_folds);
  options.cover_scene = absl::GetFlag(FLAGS_cover_scene);
  if (options.folds == 1 || options.folds < 0) {
    std::fprintf(stderr, "fovea-eval: --folds: 0 (held out) or >= 2\n");
    return kUsageError;
  }
  const bool cross_validated = options.folds >= 2;
  std::optional<LoadedModels> models;
  if (!cross_validated) {
    absl::StatusOr<LoadedModels> loaded =
        LoadModels(absl::GetFlag(FLAGS_models));
    if (!loaded.ok()) {
      std::fprintf(stderr, "fovea-eval: %s\n",
                   loaded.status().ToString().c_str());
      return kRunError;
    }
    models = *std::move(loaded);
    options.models = &*models;
  }
  options.cos_svm.c = absl::GetFlag(FLAGS_svm_c);
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);
  absl::StatusOr<MethodResults> results = EvaluateMethods(*scenes, options);
  if (!results.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 results.status().ToString().c_str());
    return kRunError;
  }
  if (cross_validated) {
    std::printf(
        "segment %s, seeds %s, %zu scenes, %d-fold cross-validated (each "
        "scene scored by models trained on the other folds)\n",
        methods.c_str(),
        std::string(ExtractionName(options.detect.extraction)).c_str(),
        scenes->size(), options.folds);
  } else {
    std::printf(
        "segment %s, seeds %s, %zu scenes, models %s as shipped (held out "
        "unless these scenes trained them)\n",
        methods.c_str(),
        std::string(ExtractionName(options.detect.extraction)).c_str(),
        scenes->size(), absl::GetFlag(FLAGS_models).c_str());
  }
  std::printf(
      "%-14s %-10s %6s %6s %6s %6s %6s %6s %6s %6s %6s %6s %6s %6s "
      "%8s %8s\n",
      "method", "kind", "scenes", "F all", "F best", "F 1st", "recall", "false",
      "wholeF", "ovl P", "ovl R", "ovl F", "bnd F", "obj.75", "1st ms",
      "all ms");
  std::vector<std::string> kinds = KindsOf(*results);
  kinds.push_back("");
  for (const SceneMethod method : options.methods) {
    for (const std::string& kind : kinds) {
      const MethodSummary s =
          SummarizeMethod(method, results->at(method), kind);
      if (s.scenes == 0) continue;
      std::printf(
          "%-14s %-10s %6d %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f "
          "%6.3f %6.3f %6.3f %6.3f %8.1f %8.1f\n",
          s.method.c_str(), kind.empty() ? "all" : kind.c_str(), s.scenes,
          s.f_all, s.f_best, s.f_first, s.object_recall, s.false_masks,
          s.whole_scene_f, s.overlap_p, s.overlap_r, s.overlap_f, s.boundary_f,
          s.objects_075, s.first_ms_median, s.total_ms_median);
    }
  }
  if (absl::GetFlag(FLAGS_json)) {
    for (const SceneMethod method : options.methods) {
      std::printf("%s\n", MethodSummaryJson(
                              SummarizeMethod(method, results->at(method), ""),
                              cross_validated, options.folds)
                              .c_str());
    }
  }
  return 0;
}

}  // namespace fovea::eval
