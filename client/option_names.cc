#include "client/option_names.h"

#include <cmath>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "core/base/status_macros.h"

namespace fovea::client {
namespace {

template <typename Enum>
using NameTable = std::vector<std::pair<absl::string_view, Enum>>;

const NameTable<fovea::v1::SaliencyOperator>& SaliencyNames() {
  static const auto* const kNames = new NameTable<fovea::v1::SaliencyOperator>{
      {"ph", fovea::v1::PH},
      {"sh", fovea::v1::SH},
      {"rso", fovea::v1::RSO},
      {"sym3d", fovea::v1::SYM3D},
      {"itti", fovea::v1::ITTI},
      {"harel", fovea::v1::HAREL},
      {"hou", fovea::v1::HOU},
      {"kootstra", fovea::v1::KOOTSTRA},
      {"target_color", fovea::v1::TARGET_COLOR},
      {"location_prior", fovea::v1::LOCATION_PRIOR},
  };
  return *kNames;
}

// Looks `text` up (case-insensitively) in `names`; `what` names the flag
// or field in the error.
template <typename Enum>
absl::StatusOr<Enum> Lookup(absl::string_view what, absl::string_view text,
                            const NameTable<Enum>& names) {
  const std::string lower =
      absl::AsciiStrToLower(absl::StripAsciiWhitespace(text));
  std::vector<absl::string_view> known;
  for (const auto& [name, value] : names) {
    if (lower == name) return value;
    known.push_back(name);
  }
  return absl::InvalidArgumentError(
      absl::StrCat(what, ": unknown name \"", text,
                   "\" (known: ", absl::StrJoin(known, ", "), ")"));
}

}  // namespace

absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ParseSaliency(
    absl::string_view text) {
  std::vector<fovea::v1::WeightedOperator> operators;
  if (absl::StripAsciiWhitespace(text).empty()) return operators;
  for (absl::string_view term : absl::StrSplit(text, '+')) {
    absl::string_view name = term;
    double weight = 1.0;
    if (const size_t colon = term.find(':'); colon != absl::string_view::npos) {
      name = term.substr(0, colon);
      const absl::string_view weight_text = term.substr(colon + 1);
      if (!absl::SimpleAtod(weight_text, &weight) || !std::isfinite(weight) ||
          weight < 0.0) {
        return absl::InvalidArgumentError(
            absl::StrCat("saliency: weight \"", weight_text, "\" of \"", name,
                         "\" is not a number >= 0"));
      }
    }
    FOVEA_ASSIGN_OR_RETURN(fovea::v1::SaliencyOperator op,
                           Lookup("saliency", name, SaliencyNames()));
    for (const fovea::v1::WeightedOperator& seen : operators) {
      if (seen.op() == op) {
        return absl::InvalidArgumentError(
            absl::StrCat("saliency: \"", name, "\" given twice"));
      }
    }
    fovea::v1::WeightedOperator& weighted = operators.emplace_back();
    weighted.set_op(op);
    weighted.set_weight(weight);
  }
  return operators;
}

absl::StatusOr<fovea::v1::Extraction> ParseExtraction(absl::string_view text) {
  static const auto* const kNames = new NameTable<fovea::v1::Extraction>{
      {"msr", fovea::v1::MSR}, {"wta", fovea::v1::WTA}, {"tj", fovea::v1::TJ}};
  return Lookup("extract", text, *kNames);
}

absl::StatusOr<fovea::v1::Pyramid> ParsePyramid(absl::string_view text) {
  static const auto* const kNames =
      new NameTable<fovea::v1::Pyramid>{{"none", fovea::v1::NONE},
                                        {"simple", fovea::v1::SIMPLE},
                                        {"itti", fovea::v1::ITTI_PYRAMID}};
  return Lookup("pyramid", text, *kNames);
}

absl::StatusOr<fovea::v1::Normalization> ParseNormalization(
    absl::string_view text) {
  static const auto* const kNames =
      new NameTable<fovea::v1::Normalization>{{"lin", fovea::v1::LIN},
                                              {"nms", fovea::v1::NMS},
                                              {"nlm", fovea::v1::NLM}};
  return Lookup("norm", text, *kNames);
}

absl::StatusOr<fovea::v1::LevelCombination> ParseLevelCombination(
    absl::string_view text) {
  static const auto* const kNames = new NameTable<fovea::v1::LevelCombination>{
      {"sum", fovea::v1::LEVELS_SUM}, {"max", fovea::v1::LEVELS_MAX}};
  return Lookup("combine", text, *kNames);
}

absl::StatusOr<fovea::v1::Fusion> ParseFusion(absl::string_view text) {
  static const auto* const kNames = new NameTable<fovea::v1::Fusion>{
      {"sum", fovea::v1::FUSION_SUM}, {"max", fovea::v1::FUSION_MAX}};
  return Lookup("fusion", text, *kNames);
}

absl::StatusOr<fovea::v1::SegmentationMethod> ParseSegmentationMethod(
    absl::string_view text) {
  static const auto* const kNames =
      new NameTable<fovea::v1::SegmentationMethod>{{"cos", fovea::v1::COS},
                                                   {"ebs", fovea::v1::EBS}};
  return Lookup("method", text, *kNames);
}

std::string SaliencyName(fovea::v1::SaliencyOperator op) {
  for (const auto& [name, value] : SaliencyNames()) {
    if (value == op) return std::string(name);
  }
  return absl::AsciiStrToLower(fovea::v1::SaliencyOperator_Name(op));
}

}  // namespace fovea::client
