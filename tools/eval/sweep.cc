#include "tools/eval/sweep.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "core/base/check.h"

namespace fovea::eval {
namespace {

constexpr const char* kKinds[] = {"boxes", "stacked", "occluded", "cylindric"};

DetectEvalOptions Options(const std::string& saliency,
                          const std::string& pyramid,
                          const std::string& combine, const std::string& norm,
                          const std::string& extract,
                          const std::string& variant) {
  DetectEvalOptions o;
  if (saliency == "pcl-clusters") {
    o.pcl_clusters = true;
    return o;
  }
  o.detect.channels.clear();
  // The grid's names are fixed and valid (FOVEA_CHECK in ThesisGrid's use).
  const absl::StatusOr<std::vector<SaliencyOp>> ops =
      ParseSaliencyOps(saliency);
  FOVEA_CHECK(ops.ok());
  for (SaliencyOp op : *ops) o.detect.channels.push_back({op, 1.0f});
  // Without a pyramid the grid's combine column is "-": the default.
  const absl::StatusOr<PyramidKind> p = ParsePyramid(pyramid);
  const absl::StatusOr<NormalizationKind> n = ParseNormalization(norm);
  FOVEA_CHECK(p.ok() && n.ok());
  o.detect.pyramid = *p;
  o.detect.level_combination =
      ParseLevelCombination(combine).value_or(LevelCombination::kSum);
  o.detect.normalization = *n;
  const absl::StatusOr<ExtractionKind> kind = ParseExtraction(extract);
  FOVEA_CHECK(kind.ok());
  o.detect.extraction = *kind;
  if (variant == "thesis") {
    o.detect.split_at_surface_edges = false;
    o.detect.tj.junction = TjJunction::kMostSalient;
    o.detect.tj.ranking = TjRanking::kMeanSaliency;
  }
  return o;
}

std::string Label(const SweepRow& r) {
  return absl::StrCat(r.saliency, "/", r.pyramid, "/", r.combine, "/", r.norm,
                      "/", r.extract, "/", r.variant);
}

}  // namespace

std::vector<SweepRow> ThesisGrid(const std::string& filter) {
  std::vector<SweepRow> rows;
  auto add = [&](const std::string& s, const std::string& p,
                 const std::string& c, const std::string& n,
                 const std::string& e) {
    const bool peer = s == "pcl-clusters";
    for (const std::string v : {"thesis", "fovea"}) {
      SweepRow row{s, p, c, n, e, peer ? "-" : v, Options(s, p, c, n, e, v)};
      if (filter.empty() || Label(row).find(filter) != std::string::npos) {
        rows.push_back(std::move(row));
      }
      if (peer) break;
    }
  };
  for (const std::string s : {"ph", "sh", "rso", "sym3d"}) {
    std::vector<std::string> extracts = {"wta", "msr"};
    if (s == "sym3d") extracts.push_back("tj");
    for (const std::string n : {"lin", "nms", "nlm"}) {
      for (const std::string& e : extracts) add(s, "none", "-", n, e);
      for (const std::string p : {"simple", "itti"}) {
        for (const std::string c : {"sum", "max"}) {
          for (const std::string& e : extracts) add(s, p, c, n, e);
        }
      }
    }
  }
  for (const std::string s : {"itti", "harel", "hou", "kootstra"}) {
    for (const std::string e : {"wta", "msr"}) add(s, "none", "-", "lin", e);
  }
  for (const std::string s : {"ph+sh+rso", "ph+sh+rso+harel"}) {
    for (const std::string e : {"wta", "msr"}) add(s, "none", "-", "lin", e);
  }
  add("pcl-clusters", "-", "-", "-", "-");
  return rows;
}

absl::Status RunSweep(const std::vector<LabelledFrame>& scenes,
                      const std::vector<SweepRow>& rows,
                      const std::string& out_dir) {
  std::filesystem::create_directories(out_dir);
  std::ofstream md(out_dir + "/sweep.md");
  std::ofstream csv(out_dir + "/sweep.csv");
  if (!md || !csv) {
    return absl::InvalidArgumentError("sweep: cannot write to " + out_dir);
  }
  md << "| saliency | pyramid | combine | norm | extract | variant | HR | DC "
        "| DC (thesis) | HR boxes | HR stacked | HR occluded | HR cylindric | "
        "ms (median) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        "---|\n";
  csv << "saliency,pyramid,combine,norm,extract,variant,hit_ratio,"
         "distance_to_center,"
         "distance_to_center_thesis,hr_boxes,hr_stacked,hr_occluded,"
         "hr_cylindric,detect_ms_median\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const SweepRow& row = rows[i];
    absl::StatusOr<DetectEvalSummary> all =
        EvaluateDetectOn(scenes, row.options);
    if (!all.ok()) {
      return absl::Status(
          all.status().code(),
          absl::StrCat(Label(row), ": ", all.status().message()));
    }
    std::vector<std::string> by_kind;
    for (const char* kind : kKinds) {
      const DetectEvalSummary k = Summarize(all->scenes, kind);
      by_kind.push_back(
          k.scenes.empty() ? "" : absl::StrFormat("%.3f", k.hit_ratio));
    }
    const std::string numbers =
        absl::StrFormat("%.3f|%.3f|%.3f|%s|%.1f", all->hit_ratio,
                        all->distance_to_center, all->distance_to_center_thesis,
                        absl::StrJoin(by_kind, "|"), all->detect_ms_median);
    md << "| " << row.saliency << " | " << row.pyramid << " | " << row.combine
       << " | " << row.norm << " | " << row.extract << " | " << row.variant
       << " | " << absl::StrJoin(absl::StrSplit(numbers, '|'), " | ") << " |\n";
    csv << row.saliency << "," << row.pyramid << "," << row.combine << ","
        << row.norm << "," << row.extract << "," << row.variant << ","
        << absl::StrJoin(absl::StrSplit(numbers, '|'), ",") << "\n";
    md.flush();
    csv.flush();
    std::fprintf(stderr, "[%zu/%zu] %-48s HR %.3f DC %.3f\n", i + 1,
                 rows.size(), Label(row).c_str(), all->hit_ratio,
                 all->distance_to_center);
  }
  return absl::OkStatus();
}

}  // namespace fovea::eval
