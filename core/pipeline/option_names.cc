// The option names of DetectOptions (detect.h): the extraction table,
// each kind's one spelling and the parsers of the text forms.
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
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
  switch (kind) {
    case PyramidKind::kNone:
      return "none";
    case PyramidKind::kSimple:
      return "simple";
    case PyramidKind::kItti:
      return "itti";
  }
  return "unknown";
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
  std::string known;
  for (const Extraction& row : kExtractions) {
    if (row.name == text) return row.kind;
    absl::StrAppend(&known, known.empty() ? "" : " ", AbslView(row.name));
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "extract: unknown strategy '", AbslView(text), "' (known: ", known, ")"));
}

absl::StatusOr<PyramidKind> ParsePyramid(std::string_view text) {
  if (text == "none") return PyramidKind::kNone;
  if (text == "simple") return PyramidKind::kSimple;
  if (text == "itti") return PyramidKind::kItti;
  return absl::InvalidArgumentError(
      absl::StrCat("pyramid: unknown kind '", AbslView(text),
                   "' (known: none simple itti)"));
}

absl::StatusOr<LevelCombination> ParseLevelCombination(std::string_view text) {
  if (text == "sum") return LevelCombination::kSum;
  if (text == "max") return LevelCombination::kMax;
  return absl::InvalidArgumentError(absl::StrCat(
      "combine: unknown combination '", AbslView(text), "' (known: sum max)"));
}

absl::StatusOr<NormalizationKind> ParseNormalization(std::string_view text) {
  if (text == "lin") return NormalizationKind::kLin;
  if (text == "nms") return NormalizationKind::kNms;
  if (text == "nlm") return NormalizationKind::kNlm;
  return absl::InvalidArgumentError(
      absl::StrCat("norm: unknown normalisation '", AbslView(text),
                   "' (known: lin nms nlm)"));
}

absl::StatusOr<FusionKind> ParseFusion(std::string_view text) {
  if (text == "sum") return FusionKind::kSum;
  if (text == "max") return FusionKind::kMax;
  return absl::InvalidArgumentError(absl::StrCat(
      "fusion: unknown fusion '", AbslView(text), "' (known: sum max)"));
}

}  // namespace fovea
