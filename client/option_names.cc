#include "client/option_names.h"

#include <google/protobuf/descriptor.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "core/base/status_macros.h"
#include "proto/enum_names.h"

namespace fovea::client {
namespace {

template <typename Enum>
using NameTable = std::vector<std::pair<absl::string_view, Enum>>;

// A table and the spellings its views point into, allocated together so
// that the one pointer kept (to `names`, the first member) reaches both.
template <typename Enum>
struct SpelledNames {
  NameTable<Enum> names;
  std::vector<std::string> spellings;
};

// The names of an enum's values, from its proto descriptor: each value's
// name in lower case ("target_color" for TARGET_COLOR), the spelling of
// core's registries (core/pipeline/saliency_registry.h, SegmentMethods in
// core/pipeline/segment.h) and of the server; the UNSPECIFIED value (0)
// has none. Never freed.
template <typename Enum>
const NameTable<Enum>* DescriptorNames(
    const google::protobuf::EnumDescriptor* values) {
  auto* table = new SpelledNames<Enum>();
  table->spellings.reserve(values->value_count());  // the views stay valid
  for (int i = 0; i < values->value_count(); ++i) {
    const google::protobuf::EnumValueDescriptor* value = values->value(i);
    if (value->number() == 0) continue;
    table->spellings.push_back(fovea::v1::ShortEnumName(*value));
    table->names.emplace_back(table->spellings.back(),
                              static_cast<Enum>(value->number()));
  }
  return &table->names;
}

const NameTable<fovea::v1::SaliencyOperator>& SaliencyNames() {
  static const auto* const kNames =
      DescriptorNames<fovea::v1::SaliencyOperator>(
          fovea::v1::SaliencyOperator_descriptor());
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
  static const auto* const kNames = DescriptorNames<fovea::v1::Extraction>(
      fovea::v1::Extraction_descriptor());
  return Lookup("extract", text, *kNames);
}

absl::StatusOr<fovea::v1::Pyramid> ParsePyramid(absl::string_view text) {
  static const auto* const kNames =
      DescriptorNames<fovea::v1::Pyramid>(fovea::v1::Pyramid_descriptor());
  return Lookup("pyramid", text, *kNames);
}

absl::StatusOr<fovea::v1::Normalization> ParseNormalization(
    absl::string_view text) {
  static const auto* const kNames = DescriptorNames<fovea::v1::Normalization>(
      fovea::v1::Normalization_descriptor());
  return Lookup("norm", text, *kNames);
}

absl::StatusOr<fovea::v1::LevelCombination> ParseLevelCombination(
    absl::string_view text) {
  static const auto* const kNames =
      DescriptorNames<fovea::v1::LevelCombination>(
          fovea::v1::LevelCombination_descriptor());
  return Lookup("combine", text, *kNames);
}

absl::StatusOr<fovea::v1::Fusion> ParseFusion(absl::string_view text) {
  static const auto* const kNames =
      DescriptorNames<fovea::v1::Fusion>(fovea::v1::Fusion_descriptor());
  return Lookup("fusion", text, *kNames);
}

absl::StatusOr<fovea::v1::SegmentationMethod> ParseSegmentationMethod(
    absl::string_view text) {
  static const auto* const kNames =
      DescriptorNames<fovea::v1::SegmentationMethod>(
          fovea::v1::SegmentationMethod_descriptor());
  return Lookup("method", text, *kNames);
}

absl::StatusOr<fovea::v1::SensorModel> ParseSensorModel(
    absl::string_view text) {
  static const auto* const kNames = DescriptorNames<fovea::v1::SensorModel>(
      fovea::v1::SensorModel_descriptor());
  return Lookup("sensor", text, *kNames);
}

std::string NameList(const google::protobuf::EnumDescriptor& type,
                     absl::string_view separator) {
  std::vector<std::string> names;
  for (int i = 0; i < type.value_count(); ++i) {
    const google::protobuf::EnumValueDescriptor* value = type.value(i);
    if (value->number() != 0) names.push_back(fovea::v1::ShortEnumName(*value));
  }
  return absl::StrJoin(names, separator);
}

namespace {

// `text` as `count` comma-separated integers in [0, max].
absl::StatusOr<std::vector<uint32_t>> ParseIntegers(absl::string_view flag,
                                                    absl::string_view text,
                                                    size_t count, uint32_t max,
                                                    absl::string_view form) {
  const std::vector<absl::string_view> parts = absl::StrSplit(text, ',');
  std::vector<uint32_t> values;
  for (absl::string_view part : parts) {
    uint32_t value = 0;
    if (!absl::SimpleAtoi(absl::StripAsciiWhitespace(part), &value) ||
        value > max) {
      values.clear();
      break;
    }
    values.push_back(value);
  }
  if (values.size() != count) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": \"", text, "\" is not ", form));
  }
  return values;
}

}  // namespace

absl::StatusOr<std::array<uint32_t, 3>> ParseRgb(absl::string_view flag,
                                                 absl::string_view text) {
  FOVEA_ASSIGN_OR_RETURN(
      const std::vector<uint32_t> values,
      ParseIntegers(flag, text, 3, 255, "R,G,B (three integers 0-255)"));
  return std::array<uint32_t, 3>{values[0], values[1], values[2]};
}

absl::StatusOr<fovea::v1::AttentionPixel> ParsePixel(absl::string_view flag,
                                                     absl::string_view text) {
  FOVEA_ASSIGN_OR_RETURN(const std::vector<uint32_t> values,
                         ParseIntegers(flag, text, 2, 1u << 20,
                                       "U,V (column,row, integers >= 0)"));
  fovea::v1::AttentionPixel pixel;
  pixel.set_u(values[0]);
  pixel.set_v(values[1]);
  return pixel;
}

std::string SaliencyName(fovea::v1::SaliencyOperator op) {
  for (const auto& [name, value] : SaliencyNames()) {
    if (value == op) return std::string(name);
  }
  const auto* value =
      fovea::v1::SaliencyOperator_descriptor()->FindValueByNumber(op);
  return value != nullptr ? fovea::v1::ShortEnumName(*value) : std::string();
}

}  // namespace fovea::client
