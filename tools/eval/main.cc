// fovea-eval: detection quality on labelled OSD-format scenes, in-process.
//
//   fovea-eval detect --data DIR [--saliency ph|sh|rso|ph+sh+rso]
//                     [--extract msr] [--json] [--out DIR] [--verbose]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
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
#include "tools/eval/detect_eval.h"
#include "tools/eval/inc_eval.h"
#include "tools/eval/json_lines.h"
#include "tools/eval/methods_eval.h"
#include "tools/eval/raw_frame_eval.h"
#include "tools/eval/room_eval.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/scorecard.h"
#include "tools/eval/sweep.h"

ABSL_FLAG(std::string, data, "",
          "OSD-format folder: *.pcd files, or a folder with learn/ inside. "
          "Defaults to $FOVEA_OSD_DIR.");
ABSL_FLAG(std::string, saliency,
          fovea::ChannelsText(fovea::DetectOptions().channels),
          "Saliency channels: ph, sh, rso, or a combination like ph+sh+rso "
          "(equal weights); or pcl-clusters, the peer: Euclidean clusters on "
          "the support plane, largest first (ignores --extract).");
ABSL_FLAG(std::string, extract,
          std::string(fovea::ExtractionName(fovea::DetectOptions().extraction)),
          "Attention-point extraction: msr, wta or tj.");
ABSL_FLAG(int, points, fovea::DetectOptions().max_points,
          "Attention points per scene at most. HR counts the first "
          "max(K, 10) of them for a scene of K objects, as the thesis's "
          "tables do, whatever this is; hit_ratio_all_points counts every "
          "point returned.");
ABSL_FLAG(std::string, pyramid,
          std::string(fovea::PyramidName(fovea::DetectOptions().pyramid)),
          "Pyramid: none, simple or itti.");
ABSL_FLAG(std::string, combine, "sum",
          "Across-scale combination with a pyramid: sum or max.");
ABSL_FLAG(std::string, norm, "lin", "Map normalisation: lin, nms or nlm.");
ABSL_FLAG(std::string, fusion, "sum", "Channel fusion: sum or max.");
ABSL_FLAG(int, sym3d_level, fovea::DetectOptions().sym3d_level,
          "Pyramid level SYM3D runs on without a pyramid.");
ABSL_FLAG(int, sym3d_kernel, fovea::DetectOptions().sym3d.kernel_size,
          "SYM3D kernel size, pixels of its level.");
ABSL_FLAG(double, tj_support, fovea::DetectOptions().tj.support_fraction,
          "TJ: components of the pixels at or above this fraction of the "
          "maximum (0: above zero, as the thesis).");
ABSL_FLAG(std::string, tj_junction, "central",
          "TJ: of several skeleton junctions take the one nearest the "
          "component's centroid (central) or the most salient (salient).");
ABSL_FLAG(std::string, tj_rank, "total",
          "TJ: rank components by total saliency (total) or by mean saliency "
          "(mean, the thesis).");
ABSL_FLAG(bool, split_edges, fovea::DetectOptions().split_at_surface_edges,
          "Zero the master map on occluding edges and concave creases "
          "before extraction (touching objects become separate components).");
ABSL_FLAG(double, edge_jump,
          fovea::DetectOptions().surface_edges.depth_jump_fraction,
          "Surface edges: depth jump, fraction of depth (0: off).");
ABSL_FLAG(double, edge_concave,
          fovea::DetectOptions().surface_edges.concave_curvature,
          "Surface edges: concave crease threshold (0: off).");
ABSL_FLAG(double, edge_concave_sharpness,
          fovea::DetectOptions().surface_edges.concave_min_curvature,
          "Surface edges: a crease's least curvature, 1/m (0: any fold).");
ABSL_FLAG(int, edge_radius, fovea::DetectOptions().surface_edges.radius_px,
          "Surface edges: neighbour distance, pixels at f = 525 px.");
ABSL_FLAG(bool, msr_inhibit_slope, true,
          "MSR also inhibits the slope around each region (false = exactly "
          "the thesis's MSR).");
ABSL_FLAG(bool, fill_holes, false,
          "Fill small depth holes by colour-guided diffusion first "
          "(thesis section 2.2).");
ABSL_FLAG(std::string, sensor,
          std::string(fovea::SensorKindName(fovea::SceneOptions().sensor)),
          "Depth noise model the thresholds follow: generic (from the "
          "intrinsics), kinect_v1 or active_stereo.");
ABSL_FLAG(int, processing_width, fovea::SceneOptions().processing_width,
          "Frames wider than this are processed reduced, pixels.");
ABSL_FLAG(bool, json, false,
          "Also print JSON, one object per line: detect a last line with "
          "scenes, hit_ratio, distance_to_center, hit_ratio_at, "
          "detect_ms_median, ...; segment one per method, rooms one per "
          "group, raw one per frame (keys: tools/eval/json_lines.h). A number "
          "that is not finite (NaN, infinity) is null, as JSON has neither.");
ABSL_FLAG(std::string, out, "",
          "Write <scene>.png (colour with object outlines | saliency map, "
          "points numbered) into this folder.");
ABSL_FLAG(bool, verbose, false, "One line per scene on stderr.");
ABSL_FLAG(std::string, method, "cos",
          "segment: cos, ebs, inc, a peer (pcl-euclidean, pcl-lccp), several "
          "of them comma-separated (one run, side by side), or all.");
ABSL_FLAG(std::string, inc_saliency, "sym3d",
          "segment --method inc: sym3d (Detect's map, F from one run) or "
          "random-points (per object 5 sequences of 5 points, section 3.3.3).");
ABSL_FLAG(std::string, seeds, "",
          "segment: where the seeds come from, tj, wta or msr (Detect's "
          "extraction; overrides --extract).");
ABSL_FLAG(int, folds, 0,
          "segment: 0 scores the models as shipped (--models); K >= 2 "
          "cross-validates instead: scene i is scored with models trained on "
          "the scenes of the other K - 1 folds.");
ABSL_FLAG(bool, cover_scene, true,
          "segment --method cos / ebs: after the attention points, seed the "
          "surfaces no mask holds yet (the server's default for all "
          "objects); false: the attention points' objects only.");
ABSL_FLAG(double, svm_c, fovea::LinearSvmTrainingOptions().c,
          "segment: the COS SVM's soft-margin penalty C.");
ABSL_FLAG(int, count, 200, "rooms: rooms per sensor and size.");
ABSL_FLAG(int, piles, 0,
          "detect / segment: evaluate on this many synthetic piles (8-16 "
          "household objects each, seeds from --seed) instead of --data.");
ABSL_FLAG(uint64_t, seed, 1, "rooms: the first room's seed.");
ABSL_FLAG(std::string, room_sensors, "kinect_v1,active_stereo",
          "rooms: sensor noise models to render with, comma-separated.");
ABSL_FLAG(std::string, sizes, "640x480",
          "rooms: resolutions, comma-separated WxH (e.g. 640x480,1280x720).");
ABSL_FLAG(std::string, models, FOVEA_DEFAULT_MODELS_DIR,
          "segment, rooms, raw: the trained models, as the server loads "
          "them.");
ABSL_FLAG(std::string, server, "",
          "replay: the server the recorded calls go to, HOST:PORT (or any "
          "fovea-client target).");
ABSL_FLAG(bool, fail_on_change, false,
          "replay: exit 3 when any record's answer changed.");
ABSL_FLAG(std::string, filter, "",
          "sweep: only the rows whose label saliency/pyramid/combine/norm/"
          "extract contains this.");

namespace fovea::eval {
namespace {

constexpr int kUsageError = 64;
constexpr int kRunError = 1;

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

}  // namespace
}  // namespace fovea::eval

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

// The scenes of --data (an OSD-format folder; its kinds.txt, if any, names
// the kinds) or of --piles (synthetic piles from --seed); nullopt after a
// message.
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

void PrintRoomSummary(const RoomSummary& s, bool json) {
  if (json) {
    std::printf("%s\n", RoomSummaryJson(s).c_str());
    return;
  }
  std::printf(
      "%-26s %6d %8.3f %8.3f %7.2f %7.3f %7.3f %7.3f %7.3f %7.3f %8.1f %8.1f\n",
      s.group.empty() ? "all" : s.group.c_str(), s.rooms, s.support_correct,
      s.object_recall, s.false_objects_per_frame, s.overlap_p, s.overlap_r,
      s.overlap_f, s.boundary_f, s.objects_075, s.first_ms_median,
      s.total_ms_median);
}

int RunRoomsCommand() {
  RoomEvalOptions options;
  options.count = absl::GetFlag(FLAGS_count);
  options.seed = absl::GetFlag(FLAGS_seed);
  options.sensors.clear();
  for (absl::string_view name :
       absl::StrSplit(absl::GetFlag(FLAGS_room_sensors), ',')) {
    absl::StatusOr<synth::RoomSensor> sensor =
        synth::ParseRoomSensor(std::string(name));
    if (!sensor.ok()) {
      std::fprintf(stderr, "fovea-eval: --room_sensors: %s\n",
                   sensor.status().ToString().c_str());
      return kUsageError;
    }
    options.sensors.push_back(*sensor);
  }
  options.sizes.clear();
  for (absl::string_view size :
       absl::StrSplit(absl::GetFlag(FLAGS_sizes), ',')) {
    const std::vector<std::string> wh = absl::StrSplit(size, 'x');
    int w = 0, h = 0;
    if (wh.size() != 2 || !absl::SimpleAtoi(wh[0], &w) ||
        !absl::SimpleAtoi(wh[1], &h)) {
      std::fprintf(stderr, "fovea-eval: --sizes: '%s' is not WxH\n",
                   std::string(size).c_str());
      return kUsageError;
    }
    options.sizes.emplace_back(w, h);
  }
  std::optional<DetectOptions> detect = DetectOptionsFromFlags();
  if (!detect) return kUsageError;
  options.run.detect = *std::move(detect);
  absl::StatusOr<SceneMethod> method =
      ParseSceneMethod(absl::GetFlag(FLAGS_method));
  if (!method.ok()) {
    std::fprintf(stderr, "fovea-eval: --method: %s\n",
                 method.status().ToString().c_str());
    return kUsageError;
  }
  options.run.method = *method;
  absl::StatusOr<LoadedModels> models = LoadModels(absl::GetFlag(FLAGS_models));
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 models.status().ToString().c_str());
    return kRunError;
  }
  options.run.models = models->View();
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);
  absl::StatusOr<std::vector<RoomResult>> results = EvaluateRooms(options);
  if (!results.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 results.status().ToString().c_str());
    return kRunError;
  }
  const bool json = absl::GetFlag(FLAGS_json);
  std::printf(
      "rooms, method %s, models %s (held out: nothing is trained on rooms)\n",
      absl::GetFlag(FLAGS_method).c_str(), absl::GetFlag(FLAGS_models).c_str());
  std::printf("%-26s %6s %8s %8s %7s %7s %7s %7s %7s %7s %8s %8s\n", "group",
              "rooms", "support", "recall", "false/f", "ovl P", "ovl R",
              "ovl F", "bnd F", "obj.75", "1st ms", "all ms");
  std::vector<std::string> groups;
  for (const RoomResult& r : *results) {
    if (std::find(groups.begin(), groups.end(), r.group) == groups.end()) {
      groups.push_back(r.group);
    }
  }
  for (const std::string& g : groups)
    PrintRoomSummary(SummarizeRooms(*results, g), false);
  PrintRoomSummary(SummarizeRooms(*results, ""), false);
  if (json) {
    for (const std::string& g : groups)
      PrintRoomSummary(SummarizeRooms(*results, g), true);
    PrintRoomSummary(SummarizeRooms(*results, ""), true);
  }
  return 0;
}

int RunRawCommand() {
  std::string data = absl::GetFlag(FLAGS_data);
  if (data.empty()) {
    const char* env = std::getenv("FOVEA_OSD_DIR");
    if (env != nullptr) data = env;
  }
  if (data.empty()) {
    std::fprintf(stderr, "fovea-eval: --data (or FOVEA_OSD_DIR) is required\n");
    return kUsageError;
  }
  SceneRunOptions options;
  std::optional<DetectOptions> detect = DetectOptionsFromFlags();
  if (!detect) return kUsageError;
  options.detect = *std::move(detect);
  absl::StatusOr<SceneMethod> method =
      ParseSceneMethod(absl::GetFlag(FLAGS_method));
  if (!method.ok()) {
    std::fprintf(stderr, "fovea-eval: --method: %s\n",
                 method.status().ToString().c_str());
    return kUsageError;
  }
  options.method = *method;
  absl::StatusOr<LoadedModels> models = LoadModels(absl::GetFlag(FLAGS_models));
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 models.status().ToString().c_str());
    return kRunError;
  }
  options.models = models->View();
  absl::StatusOr<std::vector<RawFrameResult>> results =
      EvaluateRawFrames(data, options);
  if (!results.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 results.status().ToString().c_str());
    return kRunError;
  }
  std::printf("raw frames, method %s, models %s\n",
              absl::GetFlag(FLAGS_method).c_str(),
              absl::GetFlag(FLAGS_models).c_str());
  std::printf("%-10s %-8s %6s %9s %7s %6s %6s %7s %7s %8s\n", "scene", "frame",
              "masks", "precision", "recall", "false", "ovl F", "bnd F",
              "obj.75", "ms");
  for (const RawFrameResult& r : *results) {
    for (const auto& [kind, s] :
         {std::pair<const char*, const RawFrameScore&>{"cropped", r.cropped},
          {"raw", r.raw}}) {
      std::printf("%-10s %-8s %6d %9.3f %7.3f %6d %6.3f %7.3f %7.3f %8.1f\n",
                  r.name.c_str(), kind, s.masks, s.precision, s.recall,
                  s.false_objects, s.uois.overlap_f, s.uois.boundary_f,
                  s.uois.objects_075, s.total_ms);
      if (absl::GetFlag(FLAGS_json)) {
        std::printf("%s\n", RawFrameJson(r.name, kind, s).c_str());
      }
    }
  }
  return 0;
}

int RunSweepCommand() {
  std::string data = absl::GetFlag(FLAGS_data);
  if (data.empty()) {
    const char* env = std::getenv("FOVEA_OSD_DIR");
    if (env != nullptr) data = env;
  }
  const std::string out = absl::GetFlag(FLAGS_out);
  if (data.empty() || out.empty()) {
    std::fprintf(stderr,
                 "fovea-eval sweep: --data (or FOVEA_OSD_DIR) and --out are "
                 "required\n");
    return kUsageError;
  }
  const std::vector<SweepRow> rows = ThesisGrid(absl::GetFlag(FLAGS_filter));
  absl::StatusOr<std::vector<LabelledFrame>> scenes = LoadScenes(data);
  if (!scenes.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 scenes.status().ToString().c_str());
    return kRunError;
  }
  std::fprintf(stderr, "sweep: %zu rows on %zu scenes\n", rows.size(),
               scenes->size());
  if (absl::Status s = RunSweep(*scenes, rows, out); !s.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n", s.ToString().c_str());
    return kRunError;
  }
  std::printf("wrote %s/sweep.md and %s/sweep.csv\n", out.c_str(), out.c_str());
  return 0;
}

}  // namespace
}  // namespace fovea::eval

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(
      "Detection quality on labelled OSD scenes.\n"
      "  fovea-eval detect --data DIR [--saliency ph|sh|rso|sym3d|ph+sh+rso|"
      "pcl-clusters|...] [--pyramid none|simple|itti] [--combine sum|max] "
      "[--norm lin|nms|nlm] [--extract wta|msr|tj] [--json] [--out DIR]\n"
      "  fovea-eval sweep --data DIR --out DIR [--filter TEXT]   (the grid "
      "of Tables 2.4/2.5 as Markdown and CSV)\n"
      "  fovea-eval segment --method cos|ebs|inc --data DIR [--seeds "
      "tj|wta|msr] "
      "[--inc_saliency sym3d|random-points] "
      "[--folds 5] [--json] [--out DIR]   (Table 3.1, cross-validated)\n"
      "  fovea-eval rooms [--count 200] [--seed 1] [--room_sensors "
      "kinect_v1,active_stereo] [--sizes 640x480,1280x720] [--method "
      "inc|cos|ebs|pcl-lccp|pcl-euclidean] [--models DIR] [--json] [--out "
      "DIR]   (synthetic rooms, held out: support, recall, false objects)\n"
      "  fovea-eval raw --data DIR [--method inc|cos|...]   (each raw "
      "frames/<scene>_*.png against its cropped learn/<scene>.pcd)\n"
      "  fovea-eval replay DIR --server HOST:PORT [--json] "
      "[--fail_on_change]   (the calls fovea-server --record_dir kept, sent "
      "again: points moved, masks' IoU, objects found or lost, time)\n"
      "  fovea-eval scorecard [--short] [--sets osd,...] [--methods inc,cos] "
      "[--baseline docs/scorecard.json] [--write_json F] [--out DIR]   "
      "(every kind of scene in one table; exit 3 when a figure fell below "
      "the baseline)");
  std::vector<char*> args = absl::ParseCommandLine(argc, argv);
  if (args.size() < 2) {
    std::fprintf(stderr, "%s\n",
                 std::string(absl::ProgramUsageMessage()).c_str());
    return fovea::eval::kUsageError;
  }
  const std::string command = args[1];
  if (command == "detect") return fovea::eval::RunDetectEval();
  if (command == "sweep") return fovea::eval::RunSweepCommand();
  if (command == "segment") return fovea::eval::RunSegmentEval();
  if (command == "rooms") return fovea::eval::RunRoomsCommand();
  if (command == "raw") return fovea::eval::RunRawCommand();
  if (command == "scorecard") return fovea::eval::RunScorecardCommand();
#ifdef FOVEA_EVAL_REPLAY
  if (command == "replay") {
    fovea::eval::ReplayOptions options;
    options.server = absl::GetFlag(FLAGS_server);
    return fovea::eval::RunReplay(args.size() > 2 ? args[2] : "", options,
                                  absl::GetFlag(FLAGS_json),
                                  absl::GetFlag(FLAGS_fail_on_change));
  }
#endif
  std::fprintf(stderr, "fovea-eval: unknown command '%s'\n%s\n",
               command.c_str(),
               std::string(absl::ProgramUsageMessage()).c_str());
  return fovea::eval::kUsageError;
}
