// fovea-eval rooms, raw and sweep.

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

ABSL_DECLARE_FLAG(int, count);
ABSL_DECLARE_FLAG(std::string, data);
ABSL_DECLARE_FLAG(std::string, filter);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(std::string, method);
ABSL_DECLARE_FLAG(std::string, models);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(std::string, room_sensors);
ABSL_DECLARE_FLAG(uint64_t, seed);
ABSL_DECLARE_FLAG(std::string, sizes);
ABSL_DECLARE_FLAG(bool, verbose);

namespace fovea::eval {
namespace {

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

}  // namespace

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

}  // namespace fovea::eval
