// fovea-eval realism: synthetic frames of each sensor family against that
// sensor's real frames (docs/realism.md).

#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/flags/declare.h"
#include "absl/flags/flag.h"
#include "tools/eval/commands.h"
#include "tools/eval/realism_eval.h"
#include "tools/eval/realsense_frames.h"

ABSL_DECLARE_FLAG(std::string, data);
ABSL_DECLARE_FLAG(std::string, realsense);
ABSL_DECLARE_FLAG(int, synthetic);
ABSL_DECLARE_FLAG(bool, json);
ABSL_DECLARE_FLAG(bool, verbose);

namespace fovea::eval {
namespace {

// Scenes per synthetic set when --synthetic is 0 (its default).
constexpr int kDefaultSyntheticScenes = 20;

}  // namespace

int RunRealismCommand() {
  RealismEvalOptions options;
  options.osd_dir = FlagOrEnv(absl::GetFlag(FLAGS_data), "FOVEA_OSD_DIR");
  options.realsense_dir = RealSenseDir(
      FlagOrEnv(absl::GetFlag(FLAGS_realsense), "FOVEA_REALSENSE_DIR"));
  const int synthetic = absl::GetFlag(FLAGS_synthetic);
  options.synthetic = synthetic == 0 ? kDefaultSyntheticScenes : synthetic;
  options.verbose = absl::GetFlag(FLAGS_verbose);
  if (options.osd_dir.empty() && options.realsense_dir.empty()) {
    std::fprintf(stderr,
                 "fovea-eval realism: no real frames: give --data (or "
                 "FOVEA_OSD_DIR) and/or --realsense (or "
                 "FOVEA_REALSENSE_DIR)\n");
    return kUsageError;
  }
  absl::StatusOr<std::vector<RealismComparison>> comparisons =
      RunRealism(options);
  if (!comparisons.ok()) {
    std::fprintf(stderr, "fovea-eval realism: %s\n",
                 comparisons.status().ToString().c_str());
    return comparisons.status().code() == absl::StatusCode::kInvalidArgument
               ? kUsageError
               : kRunError;
  }
  const std::string text = absl::GetFlag(FLAGS_json)
                               ? RealismJson(*comparisons) + "\n"
                               : RealismText(*comparisons);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace fovea::eval
