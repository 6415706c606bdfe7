#include "tools/eval/json_lines.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "core/base/check.h"

namespace fovea::eval {
namespace {

// Keys stay in the order they are set.
using Json = nlohmann::ordered_json;

// Rounding, as the text tables and the hand-written lines before had it.
constexpr int kScoreDecimals = 4;  // ratios, F, P, R, means per frame
constexpr int kMsDecimals = 1;     // milliseconds
constexpr int kDetectDigits = 6;   // the detect line: absl::StrCat's digits

// The number `text` spells (a finite number as printf rounded it).
double NumberOf(const std::string& text) {
  double value = 0.0;
  FOVEA_CHECK(absl::SimpleAtod(text, &value));
  return value;
}

// `value` rounded to `decimals` decimals; null when it is not finite.
Json Fixed(double value, int decimals) {
  if (!std::isfinite(value)) return nullptr;
  return NumberOf(absl::StrFormat("%.*f", decimals, value));
}

// `value` rounded to `digits` significant digits; null when not finite.
Json Significant(double value, int digits) {
  if (!std::isfinite(value)) return nullptr;
  return NumberOf(absl::StrFormat("%.*g", digits, value));
}

Json Score(double value) { return Fixed(value, kScoreDecimals); }
Json Ms(double value) { return Fixed(value, kMsDecimals); }
Json Detect(double value) { return Significant(value, kDetectDigits); }

// One line: compact, and never throwing on a string that is not UTF-8.
std::string Line(const Json& json) {
  return json.dump(/*indent=*/-1, /*indent_char=*/' ', /*ensure_ascii=*/false,
                   Json::error_handler_t::replace);
}

}  // namespace

std::string DetectSummaryJson(const DetectEvalSummary& summary,
                              const DetectEvalSummary& many) {
  Json at = Json::array();
  for (double h : summary.hit_ratio_at) at.push_back(Detect(h));
  Json json;
  json["scenes"] = summary.scenes.size();
  json["hit_ratio"] = Detect(summary.hit_ratio);
  json["hit_ratio_all_points"] = Detect(summary.hit_ratio_all_points);
  json["distance_to_center"] = Detect(summary.distance_to_center);
  json["distance_to_center_thesis"] = Detect(summary.distance_to_center_thesis);
  json["hit_ratio_at"] = std::move(at);
  json["scenes_10plus"] = many.scenes.size();
  json["hit_ratio_10plus"] = Detect(many.hit_ratio);
  json["repeated_points"] = Detect(summary.repeated_points);
  json["off_object_points"] = Detect(summary.off_object_points);
  json["detect_ms_median"] = Detect(summary.detect_ms_median);
  return Line(json);
}

// The object scores INC's and every method's summaries share, in order.
template <typename Summary>
void AddObjectScores(const Summary& summary, Json& json) {
  json["f_all"] = Score(summary.f_all);
  json["f_best"] = Score(summary.f_best);
  json["f_first"] = Score(summary.f_first);
  json["object_recall"] = Score(summary.object_recall);
  json["false_masks"] = Score(summary.false_masks);
  json["whole_scene_f"] = Score(summary.whole_scene_f);
}

std::string IncSummaryJson(const IncEvalSummary& summary) {
  Json json;
  json["scenes"] = summary.scenes.size();
  AddObjectScores(summary, json);
  return Line(json);
}

std::string MethodSummaryJson(const MethodSummary& summary,
                              bool cross_validated, int folds) {
  Json json;
  json["method"] = summary.method;
  json["evaluation"] = cross_validated ? "cross-validated" : "held-out";
  json["folds"] = cross_validated ? folds : 0;
  json["scenes"] = summary.scenes;
  AddObjectScores(summary, json);
  json["overlap_p"] = Score(summary.overlap_p);
  json["overlap_r"] = Score(summary.overlap_r);
  json["overlap_f"] = Score(summary.overlap_f);
  json["boundary_p"] = Score(summary.boundary_p);
  json["boundary_r"] = Score(summary.boundary_r);
  json["boundary_f"] = Score(summary.boundary_f);
  json["objects_075"] = Score(summary.objects_075);
  json["first_mask_ms_median"] = Ms(summary.first_ms_median);
  json["all_masks_ms_median"] = Ms(summary.total_ms_median);
  return Line(json);
}

std::string RoomSummaryJson(const RoomSummary& summary) {
  Json json;
  json["group"] = summary.group.empty() ? "all" : summary.group;
  json["rooms"] = summary.rooms;
  json["support_correct"] = Score(summary.support_correct);
  json["object_recall"] = Score(summary.object_recall);
  json["false_objects_per_frame"] = Score(summary.false_objects_per_frame);
  json["overlap_p"] = Score(summary.overlap_p);
  json["overlap_r"] = Score(summary.overlap_r);
  json["overlap_f"] = Score(summary.overlap_f);
  json["boundary_f"] = Score(summary.boundary_f);
  json["objects_075"] = Score(summary.objects_075);
  json["whole_scene_f"] = Score(summary.whole_scene_f);
  json["first_ms_median"] = Ms(summary.first_ms_median);
  json["total_ms_median"] = Ms(summary.total_ms_median);
  return Line(json);
}

std::string RawFrameJson(const std::string& scene, const std::string& frame,
                         const RawFrameScore& score) {
  Json json;
  json["scene"] = scene;
  json["frame"] = frame;
  json["masks"] = score.masks;
  json["precision"] = Score(score.precision);
  json["recall"] = Score(score.recall);
  json["false_objects"] = score.false_objects;
  json["overlap_f"] = Score(score.uois.overlap_f);
  return Line(json);
}

}  // namespace fovea::eval
