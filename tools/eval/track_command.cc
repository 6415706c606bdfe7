// fovea-eval track: the tracker on synthetic sequences of every kind.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "core/pipeline/models.h"
#include "tools/eval/commands.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/track_eval.h"

ABSL_DECLARE_FLAG(int, count);
ABSL_DECLARE_FLAG(uint64_t, seed);
ABSL_DECLARE_FLAG(std::string, models);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(int, track_frames);
ABSL_DECLARE_FLAG(std::string, kinds);
ABSL_DECLARE_FLAG(bool, pose);
ABSL_DECLARE_FLAG(std::string, data);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(bool, verbose);
ABSL_DECLARE_FLAG(double, reidentify_distance);
ABSL_DECLARE_FLAG(double, change_weight);
ABSL_DECLARE_FLAG(bool, reuse_regions);
ABSL_DECLARE_FLAG(int, region_whole_every);

namespace fovea::eval {

int RunTrackCommand() {
  absl::StatusOr<LoadedModels> models = LoadModels(absl::GetFlag(FLAGS_models));
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-eval: --models: %s\n",
                 models.status().ToString().c_str());
    return kRunError;
  }
  // Synthetic kinds by name; real scenes replayed as "osd-<replay kind>".
  std::vector<synth::SequenceKind> kinds;
  std::vector<synth::ReplayKind> replays;
  const std::string kinds_flag = absl::GetFlag(FLAGS_kinds);
  // Parses `name` from `table` into `into`; false (reported) when unknown.
  const auto parse = [](const auto& table, std::string_view what,
                        absl::string_view name, auto& into) {
    auto value = ParseNamed(table, "--kinds", what,
                            std::string_view(name.data(), name.size()));
    if (!value.ok()) {
      std::fprintf(stderr, "fovea-eval: %s\n",
                   std::string(value.status().message()).c_str());
      return false;
    }
    into.push_back(*value);
    return true;
  };
  for (absl::string_view name :
       absl::StrSplit(kinds_flag, ',', absl::SkipEmpty())) {
    const bool ok =
        absl::ConsumePrefix(&name, "osd-")
            ? parse(synth::ReplayKinds(), "replay kind", name, replays)
            : parse(synth::SequenceKinds(), "sequence kind", name, kinds);
    if (!ok) return kUsageError;
  }
  std::string data = absl::GetFlag(FLAGS_data);
  if (data.empty() && std::getenv("FOVEA_OSD_DIR") != nullptr) {
    data = std::getenv("FOVEA_OSD_DIR");
  }
  if (kinds_flag.empty()) {
    for (const auto& row : synth::SequenceKinds()) kinds.push_back(row.value);
    if (!data.empty()) {
      for (const auto& row : synth::ReplayKinds()) replays.push_back(row.value);
    }
  }
  std::vector<LabelledFrame> scenes;
  if (!replays.empty()) {
    if (data.empty()) {
      std::fprintf(stderr,
                   "fovea-eval: --kinds osd-*: no OSD data (--data or "
                   "$FOVEA_OSD_DIR)\n");
      return kUsageError;
    }
    absl::StatusOr<std::vector<LabelledFrame>> loaded = LoadScenes(data);
    if (!loaded.ok()) {
      std::fprintf(stderr, "fovea-eval: --data: %s\n",
                   loaded.status().ToString().c_str());
      return kRunError;
    }
    scenes = *std::move(loaded);
  }
  TrackEvalOptions options;
  options.count = absl::GetFlag(FLAGS_count);
  options.frames = absl::GetFlag(FLAGS_track_frames);
  options.seed = absl::GetFlag(FLAGS_seed);
  options.with_pose = absl::GetFlag(FLAGS_pose);
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);
  options.tracker.reidentify_distance =
      static_cast<float>(absl::GetFlag(FLAGS_reidentify_distance));
  options.tracker.reuse_regions = absl::GetFlag(FLAGS_reuse_regions);
  options.tracker.region_whole_every = absl::GetFlag(FLAGS_region_whole_every);
  options.tracker.segment.change_weight =
      static_cast<float>(absl::GetFlag(FLAGS_change_weight));
  if (absl::Status valid = Validate(options.tracker); !valid.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 std::string(valid.message()).c_str());
    return kUsageError;
  }
  if (options.count < 1 || options.frames < 2) {
    std::fprintf(stderr,
                 "fovea-eval: --count must be >= 1 and --track_frames >= 2\n");
    return kUsageError;
  }
  std::printf(
      "| kind | sequences | frames | IDF1 (bound) | switches / 100 "
      "object-frames | "
      "overlap F (track / single frame) | joined / split | reused / region | "
      "ms per "
      "frame (track / fresh) | cost (median / total) | changed first (track / "
      "fresh) "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  // Runs and prints one kind's figures; false on error.
  const auto report = [&](const absl::StatusOr<TrackFigures>& f) {
    if (!f.ok()) {
      std::fprintf(stderr, "fovea-eval: track: %s\n",
                   f.status().ToString().c_str());
      return false;
    }
    const double switches =
        f->identities.truth_frames == 0
            ? 0.0
            : 100.0 * f->identities.switches / f->identities.truth_frames;
    std::printf(
        "| %s | %d | %d | %.3f (%.3f) | %.2f | %.3f / %.3f | %lld / %lld | "
        "%.2f / %.2f | "
        "%.1f / "
        "%.1f | %.2fx / %.2fx | %s |\n",
        f->kind.c_str(), f->sequences, f->frames, Idf1(f->identities),
        DetectionF1(*f), switches, f->overlap_f, f->single_frame_f,
        static_cast<long long>(f->joined), static_cast<long long>(f->split),
        f->reused_fraction, f->region_fraction, f->median_track_ms,
        f->median_fresh_ms,
        f->median_fresh_ms > 0 ? f->median_track_ms / f->median_fresh_ms : 0.0,
        f->total_cost,
        f->change_frames == 0
            ? "-"
            : absl::StrFormat("%d / %d of %d", f->changed_first,
                              f->fresh_changed_first, f->change_frames)
                  .c_str());
    std::fflush(stdout);
    if (absl::GetFlag(FLAGS_json)) {
      std::printf(
          "{\"kind\":\"%s\",\"sequences\":%d,\"frames\":%d,\"idf1\":%.4f,"
          "\"detection_f1\":%.4f,\"switches_per_100\":%.3f,\"overlap_f\":%.4f,"
          "\"single_frame_f\":"
          "%.4f,\"joined\":%lld,\"split\":%lld,\"reused\":%.3f,"
          "\"region\":%.3f,"
          "\"track_ms\":%.2f,"
          "\"fresh_ms\":%.2f,\"total_cost\":%.3f,\"change_frames\":%d,"
          "\"changed_first\":%d,\"fresh_changed_first\":%d}\n",
          f->kind.c_str(), f->sequences, f->frames, Idf1(f->identities),
          DetectionF1(*f), switches, f->overlap_f, f->single_frame_f,
          static_cast<long long>(f->joined), static_cast<long long>(f->split),
          f->reused_fraction, f->region_fraction, f->median_track_ms,
          f->median_fresh_ms, f->total_cost, f->change_frames, f->changed_first,
          f->fresh_changed_first);
    }
    return true;
  };
  for (synth::SequenceKind kind : kinds) {
    if (!report(EvaluateTracking(kind, options, *models))) return kRunError;
  }
  for (synth::ReplayKind kind : replays) {
    if (!report(EvaluateReplayedTracking(kind, scenes, options, *models))) {
      return kRunError;
    }
  }
  return 0;
}

}  // namespace fovea::eval
