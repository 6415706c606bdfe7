// The scorecard's tables, its JSON baseline and the comparison with it.

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "tools/eval/scorecard.h"

namespace fovea::eval {
namespace {

double Round4(double x) { return std::round(x * 1e4) / 1e4; }

// A figure the comparison checks: its JSON key, its value in a row, and
// whether a larger value is better.
struct Figure {
  const char* key;
  double ScorecardRow::*value;
  bool higher_is_better;
};

constexpr Figure kFigures[] = {
    {"overlap_p", &ScorecardRow::overlap_p, true},
    {"overlap_r", &ScorecardRow::overlap_r, true},
    {"overlap_f", &ScorecardRow::overlap_f, true},
    {"boundary_f", &ScorecardRow::boundary_f, true},
    {"objects_075", &ScorecardRow::objects_075, true},
    {"object_recall", &ScorecardRow::object_recall, true},
    {"masks_per_object", &ScorecardRow::masks_per_object, false},
    {"false_objects", &ScorecardRow::false_objects, false},
    {"hit_ratio", &ScorecardRow::hit_ratio, true},
};

std::string Key(const std::string& set, const std::string& method,
                const std::string& kind) {
  return absl::StrCat(set, "/", method, "/", kind);
}

}  // namespace

std::string ScorecardMarkdown(const std::vector<ScorecardRow>& rows) {
  std::string out =
      "| set | method | kind | scenes | objects | overlap P / R / F | "
      "boundary F | objects F>0.75 | recall | masks / object | false / scene "
      "| HR | off-object points | no support | ms (median) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ScorecardRow& r : rows) {
    const bool realsense = r.set == "realsense";
    absl::StrAppend(
        &out,
        absl::StrFormat("| %s | %s | %s | %d | %d | ", r.set, r.method, r.kind,
                        r.scenes, r.objects),
        realsense ? "| | | "
                  : absl::StrFormat("%.3f / %.3f / %.3f | %.3f | %.3f | ",
                                    r.overlap_p, r.overlap_r, r.overlap_f,
                                    r.boundary_f, r.objects_075),
        absl::StrFormat("%.3f | %.2f | %.2f | ", r.object_recall,
                        r.masks_per_object, r.false_objects),
        realsense ? absl::StrFormat("| | %d (table hits %d) | ", r.no_support,
                                    r.table_hits)
                  : absl::StrFormat("%.3f | %.1f | %d | ", r.hit_ratio,
                                    r.off_object_points, r.no_support),
        absl::StrFormat("%.0f |\n", r.total_ms_median));
  }
  return out;
}

std::string RealismMarkdown(const std::vector<RealismComparison>& realism) {
  std::string out =
      "| realism: sensor | real | synthetic | mean KS | largest KS | "
      "(statistic) |\n|---|---|---|---|---|---|\n";
  for (const RealismComparison& c : realism) {
    const RealismSummary s = SummarizeRealism(c.rows, "");
    absl::StrAppend(
        &out,
        absl::StrFormat("| %s | %s | %s | %.3f | %.3f | %s |\n", c.sensor,
                        c.real, c.synthetic, s.mean_ks, s.max_ks, s.worst));
  }
  return out;
}

std::string ScorecardJson(const std::vector<ScorecardRow>& rows,
                          const std::vector<RealismComparison>& realism) {
  nlohmann::ordered_json doc =
      nlohmann::ordered_json::parse(ScorecardJson(rows));
  if (realism.empty()) return doc.dump(1);
  doc["realism"] = nlohmann::ordered_json::array();
  for (const RealismComparison& c : realism) {
    const RealismSummary s = SummarizeRealism(c.rows, "");
    nlohmann::ordered_json row;
    row["sensor"] = c.sensor;
    row["real"] = c.real;
    row["synthetic"] = c.synthetic;
    row["mean_ks"] = Round4(s.mean_ks);
    row["max_ks"] = Round4(s.max_ks);
    row["worst"] = s.worst;
    doc["realism"].push_back(std::move(row));
  }
  return doc.dump(1);
}

absl::StatusOr<std::vector<std::string>> CompareRealismRows(
    const std::vector<RealismComparison>& realism,
    const std::string& baseline_json) {
  const nlohmann::json doc =
      nlohmann::json::parse(baseline_json, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) {
    return absl::InvalidArgumentError(
        "scorecard baseline: not a JSON document");
  }
  std::vector<std::string> falls;
  if (!doc.contains("realism") || !doc["realism"].is_array()) return falls;
  for (const nlohmann::json& b : doc["realism"]) {
    if (!b.is_object() || !b.contains("real") || !b["real"].is_string() ||
        !b.contains("synthetic") || !b["synthetic"].is_string() ||
        !b.contains("mean_ks") || !b["mean_ks"].is_number()) {
      continue;
    }
    for (const RealismComparison& c : realism) {
      if (c.real != b["real"].get<std::string>() ||
          c.synthetic != b["synthetic"].get<std::string>()) {
        continue;
      }
      const double base = b["mean_ks"].get<double>();
      const double now = Round4(SummarizeRealism(c.rows, "").mean_ks);
      // A statistic that had samples and has none now is a fall too.
      if (std::isnan(now) || now > base + kRealismMargin + 1e-9) {
        falls.push_back(absl::StrFormat(
            "realism/%s/%s mean_ks %.4f -> %.4f (baseline %.4f, margin %.2f)",
            c.real, c.synthetic, base, now, base, kRealismMargin));
      }
    }
  }
  return falls;
}

std::string ScorecardJson(const std::vector<ScorecardRow>& rows) {
  nlohmann::ordered_json doc;
  doc["rows"] = nlohmann::ordered_json::array();
  for (const ScorecardRow& r : rows) {
    nlohmann::ordered_json row;
    row["set"] = r.set;
    row["method"] = r.method;
    row["kind"] = r.kind;
    row["evaluation"] = r.evaluation;
    row["scenes"] = r.scenes;
    row["objects"] = r.objects;
    for (const Figure& f : kFigures) row[f.key] = Round4(r.*f.value);
    row["off_object_points"] = Round4(r.off_object_points);
    row["no_support"] = r.no_support;
    row["table_hits"] = r.table_hits;
    row["total_ms_median"] = std::round(r.total_ms_median * 10) / 10;
    doc["rows"].push_back(std::move(row));
  }
  return doc.dump(1);
}

absl::StatusOr<std::vector<std::string>> CompareScorecard(
    const std::vector<ScorecardRow>& rows, const std::string& baseline_json) {
  const nlohmann::json doc =
      nlohmann::json::parse(baseline_json, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.contains("rows") || !doc["rows"].is_array()) {
    return absl::InvalidArgumentError(
        "scorecard baseline: not a JSON document with a \"rows\" array");
  }
  std::vector<std::string> falls;
  for (const nlohmann::json& b : doc["rows"]) {
    if (!b.is_object() || !b.contains("set") || !b.contains("method") ||
        !b.contains("kind")) {
      return absl::InvalidArgumentError(
          "scorecard baseline: a row without set, method and kind");
    }
    const std::string key =
        Key(b["set"].get<std::string>(), b["method"].get<std::string>(),
            b["kind"].get<std::string>());
    for (const ScorecardRow& r : rows) {
      if (Key(r.set, r.method, r.kind) != key) continue;
      for (const Figure& f : kFigures) {
        if (!b.contains(f.key) || !b[f.key].is_number()) continue;
        const double base = b[f.key].get<double>();
        const double now = Round4(r.*f.value);
        const double margin = f.higher_is_better ? kScoreMargin : kCountMargin;
        const bool fell = f.higher_is_better ? now < base - margin - 1e-9
                                             : now > base + margin + 1e-9;
        if (fell) {
          falls.push_back(
              absl::StrFormat("%s %s %.4f -> %.4f (baseline %.4f, margin %.2f)",
                              key, f.key, base, now, base, margin));
        }
      }
    }
  }
  return falls;
}

}  // namespace fovea::eval
