// The option names of DetectOptions (detect.h): the extraction table,
// each kind's one spelling and the parsers of the text forms.
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/base/name_table.h"
#include "core/base/strings.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/saliency_registry.h"

namespace fovea {
namespace {

absl::StatusOr<std::vector<AttentionPoint>> Msr(const cv::Mat& master,
                                                const DetectOptions& options) {
  return ExtractMsrPoints(master, options.max_points, options.msr);
}
absl::StatusOr<std::vector<AttentionPoint>> Wta(const cv::Mat& master,
                                                const DetectOptions& options) {
  return ExtractWtaPoints(master, options.max_points, options.wta);
}
absl::StatusOr<std::vector<AttentionPoint>> Tj(const cv::Mat& master,
                                               const DetectOptions& options) {
  return ExtractTjPoints(master, options.max_points, options.tj);
}

constexpr Extraction kExtractions[] = {
    {ExtractionKind::kMsr, "msr", &Msr},
    {ExtractionKind::kWta, "wta", &Wta},
    {ExtractionKind::kTj, "tj", &Tj},
};

}  // namespace

std::string_view SaliencyOpName(SaliencyOp op) {
  const SaliencyOperator* row = FindSaliencyOperator(op);
  return row != nullptr ? row->name : "unknown";
}

absl::Span<const Extraction> Extractions() { return kExtractions; }

std::string_view ExtractionName(ExtractionKind kind) {
  for (const Extraction& row : kExtractions) {
    if (row.kind == kind) return row.name;
  }
  return "unknown";
}

std::string_view PyramidName(PyramidKind kind) {
  return NameOf(PyramidKinds(), kind);
}

std::string ChannelsText(const std::vector<WeightedChannel>& channels) {
  std::string text;
  for (const WeightedChannel& c : channels) {
    if (!text.empty()) text += '+';
    text += SaliencyOpName(c.op);
  }
  return text;
}

absl::StatusOr<std::vector<SaliencyOp>> ParseSaliencyOps(
    std::string_view text) {
  std::vector<SaliencyOp> ops;
  for (absl::string_view part : absl::StrSplit(AbslView(text), '+')) {
    const SaliencyOperator* row =
        FindSaliencyOperator(std::string_view(part.data(), part.size()));
    if (row == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(
          "saliency: unknown operator '", part,
          "' (known: ", SaliencyOperatorNames(), ", combined with '+')"));
    }
    ops.push_back(row->op);
  }
  return ops;
}

absl::StatusOr<ExtractionKind> ParseExtraction(std::string_view text) {
  for (const Extraction& row : kExtractions) {
    if (row.name == text) return row.kind;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("extract: unknown strategy '", AbslView(text),
                   "' (known: ", ExtractionNames(), ")"));
}

absl::Span<const NamedValue<PyramidKind>> PyramidKinds() {
  static constexpr NamedValue<PyramidKind> kTable[] = {
      {PyramidKind::kNone, "none"},
      {PyramidKind::kSimple, "simple"},
      {PyramidKind::kItti, "itti"}};
  return kTable;
}

absl::Span<const NamedValue<LevelCombination>> LevelCombinations() {
  static constexpr NamedValue<LevelCombination> kTable[] = {
      {LevelCombination::kSum, "sum"}, {LevelCombination::kMax, "max"}};
  return kTable;
}

absl::Span<const NamedValue<NormalizationKind>> NormalizationKinds() {
  static constexpr NamedValue<NormalizationKind> kTable[] = {
      {NormalizationKind::kLin, "lin"},
      {NormalizationKind::kNms, "nms"},
      {NormalizationKind::kNlm, "nlm"}};
  return kTable;
}

absl::Span<const NamedValue<FusionKind>> FusionKinds() {
  static constexpr NamedValue<FusionKind> kTable[] = {
      {FusionKind::kSum, "sum"}, {FusionKind::kMax, "max"}};
  return kTable;
}

std::string ExtractionNames(std::string_view separator) {
  std::string names;
  for (const Extraction& row : kExtractions) {
    absl::StrAppend(&names, names.empty() ? "" : AbslView(separator),
                    AbslView(row.name));
  }
  return names;
}

absl::StatusOr<PyramidKind> ParsePyramid(std::string_view text) {
  return ParseNamed(PyramidKinds(), "pyramid", "kind", text);
}

absl::StatusOr<LevelCombination> ParseLevelCombination(std::string_view text) {
  return ParseNamed(LevelCombinations(), "combine", "combination", text);
}

absl::StatusOr<NormalizationKind> ParseNormalization(std::string_view text) {
  return ParseNamed(NormalizationKinds(), "norm", "normalisation", text);
}

absl::StatusOr<FusionKind> ParseFusion(std::string_view text) {
  return ParseNamed(FusionKinds(), "fusion", "fusion", text);
}

}  // namespace fovea
