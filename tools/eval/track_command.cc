// fovea-eval track: the tracker on synthetic sequences of every kind.

#include <cstdio>
#include <string>
#include <vector>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "absl/strings/str_split.h"
#include "core/pipeline/models.h"
#include "tools/eval/commands.h"
#include "tools/eval/track_eval.h"

ABSL_DECLARE_FLAG(int, count);
ABSL_DECLARE_FLAG(uint64_t, seed);
ABSL_DECLARE_FLAG(std::string, models);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(int, track_frames);
ABSL_DECLARE_FLAG(std::string, kinds);
ABSL_DECLARE_FLAG(bool, pose);

namespace fovea::eval {

int RunTrackCommand() {
  absl::StatusOr<LoadedModels> models = LoadModels(absl::GetFlag(FLAGS_models));
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-eval: --models: %s\n",
                 models.status().ToString().c_str());
    return kRunError;
  }
  std::vector<synth::SequenceKind> kinds;
  const std::string kinds_flag = absl::GetFlag(FLAGS_kinds);
  for (absl::string_view name :
       absl::StrSplit(kinds_flag, ',', absl::SkipEmpty())) {
    absl::StatusOr<synth::SequenceKind> kind =
        ParseNamed(synth::SequenceKinds(), "--kinds", "sequence kind",
                   std::string_view(name.data(), name.size()));
    if (!kind.ok()) {
      std::fprintf(stderr, "fovea-eval: %s\n",
                   std::string(kind.status().message()).c_str());
      return kUsageError;
    }
    kinds.push_back(*kind);
  }
  if (kinds_flag.empty()) {
    for (const auto& row : synth::SequenceKinds()) kinds.push_back(row.value);
  }
  TrackEvalOptions options;
  options.count = absl::GetFlag(FLAGS_count);
  options.frames = absl::GetFlag(FLAGS_track_frames);
  options.seed = absl::GetFlag(FLAGS_seed);
  options.with_pose = absl::GetFlag(FLAGS_pose);
  if (options.count < 1 || options.frames < 2) {
    std::fprintf(stderr,
                 "fovea-eval: --count must be >= 1 and --track_frames >= 2\n");
    return kUsageError;
  }
  std::printf(
      "| kind | sequences | frames | IDF1 | switches / 100 object-frames | "
      "overlap F (track / single frame) | joined | reused | ms per frame "
      "(track / fresh) | cost |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (synth::SequenceKind kind : kinds) {
    absl::StatusOr<TrackFigures> f = EvaluateTracking(kind, options, *models);
    if (!f.ok()) {
      std::fprintf(stderr, "fovea-eval: track: %s\n",
                   f.status().ToString().c_str());
      return kRunError;
    }
    const double switches =
        f->identities.truth_frames == 0
            ? 0.0
            : 100.0 * f->identities.switches / f->identities.truth_frames;
    std::printf(
        "| %s | %d | %d | %.3f | %.2f | %.3f / %.3f | %lld | %.2f | %.1f / "
        "%.1f | %.2fx |\n",
        f->kind.c_str(), f->sequences, f->frames, Idf1(f->identities), switches,
        f->overlap_f, f->single_frame_f, static_cast<long long>(f->joined),
        f->reused_fraction, f->median_track_ms, f->median_fresh_ms,
        f->median_fresh_ms > 0 ? f->median_track_ms / f->median_fresh_ms : 0.0);
    std::fflush(stdout);
    if (absl::GetFlag(FLAGS_json)) {
      std::printf(
          "{\"kind\":\"%s\",\"sequences\":%d,\"frames\":%d,\"idf1\":%.4f,"
          "\"switches_per_100\":%.3f,\"overlap_f\":%.4f,\"single_frame_f\":"
          "%.4f,\"joined\":%lld,\"reused\":%.3f,\"track_ms\":%.2f,"
          "\"fresh_ms\":%.2f}\n",
          f->kind.c_str(), f->sequences, f->frames, Idf1(f->identities),
          switches, f->overlap_f, f->single_frame_f,
          static_cast<long long>(f->joined), f->reused_fraction,
          f->median_track_ms, f->median_fresh_ms);
    }
  }
  return 0;
}

}  // namespace fovea::eval
