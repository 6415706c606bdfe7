// fovea-eval scorecard: its flags and the command (scorecard.h).

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "core/pipeline/models.h"
#include "tools/eval/commands.h"
#include "tools/eval/realsense_frames.h"
#include "tools/eval/scorecard.h"

ABSL_DECLARE_FLAG(std::string, data);
ABSL_DECLARE_FLAG(std::string, models);
ABSL_DECLARE_FLAG(std::string, out);
ABSL_DECLARE_FLAG(bool, verbose);
ABSL_DECLARE_FLAG(bool, json);

ABSL_FLAG(bool, short, false,
          "scorecard: the short form CI runs (the sets osd, osd-rot90, "
          "stacked and realsense, each exactly as in the full form).");
ABSL_FLAG(std::string, sets, "",
          "scorecard: sets to run, comma-separated (osd, osd-rot90, "
          "osd-rot180, osd-half, piles, stacked, stacked-crop, stacked-above, "
          "rooms, "
          "realsense, realism); empty: all (or the short form's with "
          "--short).");
ABSL_FLAG(std::string, methods, "inc",
          "scorecard: methods, comma-separated (inc, cos, ebs).");
ABSL_FLAG(int, synthetic, 0,
          "scorecard: scenes per synthetic set and sensor (piles, stacked, "
          "rooms); 0: the sets' own counts (40, 30, 30), which the baseline "
          "was measured with.");
ABSL_FLAG(std::string, realsense, "",
          "scorecard: the RealSense frames' folder. Defaults to "
          "$FOVEA_REALSENSE_DIR.");
ABSL_FLAG(std::string, baseline, "",
          "scorecard: compare with this baseline (docs/scorecard.json); exit "
          "3 when a figure fell beyond its margin.");
ABSL_FLAG(std::string, write_json, "",
          "scorecard: write the rows as JSON here (a new baseline).");
ABSL_FLAG(std::string, write_markdown, "",
          "scorecard: write the rows as a Markdown table here.");

namespace fovea::eval {
namespace {

constexpr int kFell = 3;

bool WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

}  // namespace

std::string FlagOrEnv(const std::string& flag, const char* name) {
  if (!flag.empty()) return flag;
  const char* env = std::getenv(name);
  return env == nullptr ? "" : env;
}

int RunScorecardCommand() {
  ScorecardOptions options;
  options.methods.clear();
  for (absl::string_view name :
       absl::StrSplit(absl::GetFlag(FLAGS_methods), ',')) {
    absl::StatusOr<SceneMethod> method =
        ParseSceneMethod(std::string_view(name.data(), name.size()));
    if (!method.ok() || *method == SceneMethod::kPclLccp ||
        *method == SceneMethod::kPclEuclidean) {
      std::fprintf(stderr, "fovea-eval: --methods: inc, cos or ebs, got '%s'\n",
                   std::string(name).c_str());
      return kUsageError;
    }
    options.methods.push_back(*method);
  }
  const std::string sets = absl::GetFlag(FLAGS_sets);
  if (!sets.empty()) {
    for (absl::string_view s : absl::StrSplit(sets, ',')) {
      options.sets.emplace_back(s);
    }
  } else if (absl::GetFlag(FLAGS_short)) {
    options.sets = {"osd", "osd-rot90", "stacked", "realsense"};
  }
  options.osd_dir = FlagOrEnv(absl::GetFlag(FLAGS_data), "FOVEA_OSD_DIR");
  options.realsense_dir =
      FlagOrEnv(absl::GetFlag(FLAGS_realsense), "FOVEA_REALSENSE_DIR");
  absl::StatusOr<LoadedModels> models = LoadModels(absl::GetFlag(FLAGS_models));
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 models.status().ToString().c_str());
    return kRunError;
  }
  options.models = &*models;
  if (const int n = absl::GetFlag(FLAGS_synthetic); n > 0) {
    options.piles = options.stacked = options.rooms = n;
  }
  options.out_dir = absl::GetFlag(FLAGS_out);
  options.verbose = absl::GetFlag(FLAGS_verbose);
  absl::StatusOr<std::vector<ScorecardRow>> rows = RunScorecard(options);
  if (!rows.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n", rows.status().ToString().c_str());
    return kRunError;
  }
  std::printf(
      "scorecard, methods %s, models %s (osd*: leave-one-kind-out; the rest "
      "held out)%s%s\n",
      absl::GetFlag(FLAGS_methods).c_str(), absl::GetFlag(FLAGS_models).c_str(),
      options.osd_dir.empty() ? "; no OSD data: osd sets skipped" : "",
      options.realsense_dir.empty() ? "; no RealSense frames: skipped" : "");
  std::printf("%s", ScorecardMarkdown(*rows).c_str());
  // The realism rows: with the full form, or when --sets names them.
  std::vector<RealismComparison> realism;
  const bool wants_realism =
      sets.empty()
          ? !absl::GetFlag(FLAGS_short)
          : absl::StrContains(absl::StrCat(",", sets, ","), ",realism,");
  if (wants_realism &&
      !(options.osd_dir.empty() && options.realsense_dir.empty())) {
    RealismEvalOptions realism_options;
    realism_options.osd_dir = options.osd_dir;
    realism_options.realsense_dir = RealSenseDir(options.realsense_dir);
    absl::StatusOr<std::vector<RealismComparison>> r =
        RunRealism(realism_options);
    if (!r.ok()) {
      std::fprintf(stderr, "fovea-eval: realism: %s\n",
                   r.status().ToString().c_str());
      return kRunError;
    }
    realism = *std::move(r);
    std::printf("\n%s", RealismMarkdown(realism).c_str());
  }
  if (absl::GetFlag(FLAGS_json)) {
    std::printf("%s\n", ScorecardJson(*rows, realism).c_str());
  }
  if (const std::string path = absl::GetFlag(FLAGS_write_json); !path.empty()) {
    if (!WriteText(path, ScorecardJson(*rows, realism) + "\n")) {
      std::fprintf(stderr, "fovea-eval: cannot write %s\n", path.c_str());
      return kRunError;
    }
  }
  if (const std::string path = absl::GetFlag(FLAGS_write_markdown);
      !path.empty()) {
    if (!WriteText(path, ScorecardMarkdown(*rows))) {
      std::fprintf(stderr, "fovea-eval: cannot write %s\n", path.c_str());
      return kRunError;
    }
  }
  const std::string baseline = absl::GetFlag(FLAGS_baseline);
  if (baseline.empty()) return 0;
  std::ifstream in(baseline);
  if (!in) {
    std::fprintf(stderr, "fovea-eval: --baseline: cannot read %s\n",
                 baseline.c_str());
    return kRunError;
  }
  std::stringstream text;
  text << in.rdbuf();
  absl::StatusOr<std::vector<std::string>> falls =
      CompareScorecard(*rows, text.str());
  absl::StatusOr<std::vector<std::string>> realism_falls =
      CompareRealismRows(realism, text.str());
  if (!falls.ok() || !realism_falls.ok()) {
    std::fprintf(stderr, "fovea-eval: %s\n",
                 (!falls.ok() ? falls.status() : realism_falls.status())
                     .ToString()
                     .c_str());
    return kRunError;
  }
  falls->insert(falls->end(), realism_falls->begin(), realism_falls->end());
  if (falls->empty()) {
    std::printf("scorecard: no figure fell beyond its margin against %s\n",
                baseline.c_str());
    return 0;
  }
  std::printf("scorecard: %zu figures fell beyond their margins against %s:\n",
              falls->size(), baseline.c_str());
  for (const std::string& f : *falls) std::printf("  %s\n", f.c_str());
  std::printf(
      "A fall that is meant must be a commit of its own that rewrites the "
      "baseline and says why (docs/scorecard.md).\n");
  return kFell;
}

}  // namespace fovea::eval
