#ifndef FOVEA_TOOLS_EVAL_SWEEP_H_
#define FOVEA_TOOLS_EVAL_SWEEP_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/frame/osd_pcd.h"
#include "tools/eval/detect_eval.h"

namespace fovea::eval {

// One row of the grid of the thesis's Tables 2.4 and 2.5.
struct SweepRow {
  std::string saliency;  // "ph", "ph+sh+rso+harel", "pcl-clusters", ...
  std::string pyramid;   // "none", "simple", "itti" ("-" for the peer)
  std::string combine;   // "sum", "max" ("-" without a pyramid)
  std::string norm;      // "lin", "nms", "nlm"
  std::string extract;   // "wta", "msr", "tj"
  // "thesis": the thesis's master map and TJ (no surface-edge split, the
  // most salient junction, regions ranked by mean saliency); "fovea": the
  // defaults of DetectOptions for those three.
  std::string variant;
  DetectEvalOptions options;
};

// The grid: each 3D map (ph, sh, rso, sym3d) x {single level, SIMPLE, ITTI}
// x {SUM, MAX} (pyramids only) x {LIN, NMS, NLM} x {WTA, MSR, and TJ for
// SYM3D}; the colour maps with WTA and MSR; PH+SH+RSO with and without
// HAREL; each in the "thesis" and the "fovea" variant; the pcl-clusters
// peer. `filter` keeps the rows whose label
// ("saliency/pyramid/combine/norm/extract/variant") contains it.
std::vector<SweepRow> ThesisGrid(const std::string& filter);

// Evaluates every row on `scenes` and writes <out_dir>/sweep.md (a table
// laid out like the thesis's: HR, DC, the thesis's DC, HR per scene kind,
// median Detect ms) and <out_dir>/sweep.csv. Progress on stderr.
absl::Status RunSweep(const std::vector<LabelledFrame>& scenes,
                      const std::vector<SweepRow>& rows,
                      const std::string& out_dir);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SWEEP_H_
