#include "core/segmentation/linear_svm.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/segmentation/svm_common.h"

namespace fovea {
namespace {

using svm_internal::ParseNumber;

constexpr std::string_view kMagic = "fovea-linear-svm 1";
// Longest model text Parse reads, bytes (a model is a few hundred).
constexpr size_t kMaxModelBytes = 1 << 20;

}  // namespace

LinearSvm::LinearSvm(std::string kind, std::vector<std::string> feature_names,
                     std::vector<double> weights, double bias,
                     std::string provenance)
    : kind_(std::move(kind)),
      feature_names_(std::move(feature_names)),
      weights_(std::move(weights)),
      bias_(bias),
      provenance_(std::move(provenance)) {}

double LinearSvm::Decision(const std::vector<double>& x) const {
  double f = bias_;
  for (size_t i = 0; i < weights_.size() && i < x.size(); ++i) {
    f += weights_[i] * x[i];
  }
  return f;
}

std::string LinearSvm::Version() const {
  return absl::StrFormat("%s-%016x", kind_, svm_internal::Fnv1a(Serialize()));
}

std::string LinearSvm::Serialize() const {
  std::vector<std::string> weights;
  for (const double w : weights_)
    weights.push_back(absl::StrFormat("%.17g", w));
  std::string provenance = provenance_;
  for (char& c : provenance) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return absl::StrCat(AbslView(kMagic), "\nkind ", kind_, "\nfeatures ",
                      absl::StrJoin(feature_names_, " "), "\nweights ",
                      absl::StrJoin(weights, " "), "\nbias ",
                      absl::StrFormat("%.17g", bias_), "\nprovenance ",
                      provenance, "\n");
}

absl::StatusOr<LinearSvm> LinearSvm::Parse(std::string_view text,
                                           std::string_view expected_kind) {
  if (text.size() > kMaxModelBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("model text is ", text.size(), " bytes, more than ",
                     kMaxModelBytes, ": not a linear SVM"));
  }
  const std::vector<absl::string_view> lines =
      absl::StrSplit(AbslView(text), '\n', absl::SkipEmpty());
  if (lines.empty() || lines[0] != AbslView(kMagic)) {
    return absl::InvalidArgumentError(
        absl::StrCat("line 1: expected '", AbslView(kMagic),
                     "' (not a Fovea linear SVM, "
                     "or another format version)"));
  }
  std::string kind;
  std::vector<std::string> features;
  std::vector<double> weights;
  double bias = 0.0;
  std::string provenance;
  bool seen[5] = {false, false, false, false, false};
  constexpr const char* kKeys[5] = {"kind", "features", "weights", "bias",
                                    "provenance"};
  for (size_t i = 1; i < lines.size(); ++i) {
    const int line = static_cast<int>(i + 1);
    const std::pair<absl::string_view, absl::string_view> kv =
        absl::StrSplit(lines[i], absl::MaxSplits(' ', 1));
    int key = -1;
    for (int k = 0; k < 5; ++k) {
      if (kv.first == kKeys[k]) key = k;
    }
    if (key < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("line ", line, ": unknown key '", kv.first, "'"));
    }
    if (seen[key]) {
      return absl::InvalidArgumentError(
          absl::StrCat("line ", line, ": '", kKeys[key], "' repeated"));
    }
    seen[key] = true;
    const std::vector<absl::string_view> words =
        absl::StrSplit(kv.second, ' ', absl::SkipEmpty());
    switch (key) {
      case 0:
        kind = std::string(kv.second);
        break;
      case 1:
        for (absl::string_view w : words) features.emplace_back(w);
        break;
      case 2:
        for (absl::string_view w : words) {
          FOVEA_ASSIGN_OR_RETURN(
              double v,
              ParseNumber(std::string_view(w.data(), w.size()), line));
          weights.push_back(v);
        }
        break;
      case 3: {
        FOVEA_ASSIGN_OR_RETURN(
            double v,
            ParseNumber(std::string_view(kv.second.data(), kv.second.size()),
                        line));
        bias = v;
        break;
      }
      default:
        provenance = std::string(kv.second);
    }
  }
  for (int k = 0; k < 4; ++k) {
    if (!seen[k]) {
      return absl::InvalidArgumentError(
          absl::StrCat("missing the '", kKeys[k], "' line"));
    }
  }
  if (kind != expected_kind) {
    return absl::InvalidArgumentError(absl::StrCat(
        "kind is '", kind, "', expected '", AbslView(expected_kind), "'"));
  }
  if (features.empty() || weights.size() != features.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(weights.size(), " weights for ", features.size(),
                     " features; they must match and not be empty"));
  }
  return LinearSvm(std::move(kind), std::move(features), std::move(weights),
                   bias, std::move(provenance));
}

}  // namespace fovea
