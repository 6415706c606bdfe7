#include "core/segmentation/rbf_svm.h"

#include <cmath>
#include <cstdlib>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/segmentation/svm_common.h"

namespace fovea {
namespace {

using svm_internal::ParseNumber;

constexpr std::string_view kMagic = "fovea-rbf-svm 1";

std::string Number(double v) { return absl::StrFormat("%.17g", v); }

}  // namespace

RbfSvm::RbfSvm(std::string kind, std::vector<std::string> feature_names,
               double gamma, std::vector<std::vector<double>> support_vectors,
               std::vector<double> coefficients, double rho, double prob_a,
               double prob_b, std::string provenance)
    : kind_(std::move(kind)),
      feature_names_(std::move(feature_names)),
      gamma_(gamma),
      support_vectors_(std::move(support_vectors)),
      coefficients_(std::move(coefficients)),
      rho_(rho),
      prob_a_(prob_a),
      prob_b_(prob_b),
      provenance_(std::move(provenance)) {}

double RbfSvm::Decision(const std::vector<double>& x) const {
  double f = -rho_;
  for (size_t i = 0; i < support_vectors_.size(); ++i) {
    const std::vector<double>& sv = support_vectors_[i];
    double d2 = 0.0;
    for (size_t k = 0; k < sv.size() && k < x.size(); ++k) {
      const double d = x[k] - sv[k];
      d2 += d * d;
    }
    f += coefficients_[i] * std::exp(-gamma_ * d2);
  }
  return f;
}

double RbfSvm::Probability(const std::vector<double>& x) const {
  // With f = our decision (positive for +1): p(+1) = 1 / (1 + exp(A f0 + B))
  // where f0 = f for label[0] = +1; see TrainModel for the sign cases.
  const double f = Decision(x);
  const double t = prob_a_ * f + prob_b_;
  // Numerically stable logistic of -t.
  return t >= 0.0 ? std::exp(-t) / (1.0 + std::exp(-t))
                  : 1.0 / (1.0 + std::exp(t));
}

std::string RbfSvm::Version() const {
  return absl::StrFormat("%s-%016x", kind_, svm_internal::Fnv1a(Serialize()));
}

std::string RbfSvm::Serialize() const {
  std::string provenance = provenance_;
  for (char& c : provenance) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  std::string text = absl::StrCat(
      AbslView(kMagic), "\nkind ", kind_, "\nfeatures ",
      absl::StrJoin(feature_names_, " "), "\ngamma ", Number(gamma_), "\nrho ",
      Number(rho_), "\nprobability ", Number(prob_a_), " ", Number(prob_b_),
      "\nprovenance ", provenance, "\nvectors ", support_vectors_.size(), "\n");
  for (size_t i = 0; i < support_vectors_.size(); ++i) {
    absl::StrAppend(&text, Number(coefficients_[i]));
    for (const double v : support_vectors_[i]) {
      absl::StrAppend(&text, " ", Number(v));
    }
    absl::StrAppend(&text, "\n");
  }
  return text;
}

absl::StatusOr<RbfSvm> RbfSvm::Parse(std::string_view text,
                                     std::string_view expected_kind) {
  const std::vector<absl::string_view> lines =
      absl::StrSplit(AbslView(text), '\n', absl::SkipEmpty());
  if (lines.empty() || lines[0] != AbslView(kMagic)) {
    return absl::InvalidArgumentError(
        absl::StrCat("line 1: expected '", AbslView(kMagic),
                     "' (not a Fovea RBF SVM, or another format version)"));
  }
  constexpr const char* kKeys[] = {"kind",        "features",   "gamma",  "rho",
                                   "probability", "provenance", "vectors"};
  constexpr int kHeader = 7;
  if (lines.size() < 1 + kHeader) {
    return absl::InvalidArgumentError(
        absl::StrCat("only ", lines.size(), " lines: the header is cut off"));
  }
  std::string kind;
  std::vector<std::string> features;
  double gamma = 0, rho = 0, prob_a = 0, prob_b = 0;
  std::string provenance;
  int64_t count = 0;
  for (int k = 0; k < kHeader; ++k) {
    const int line = k + 2;
    const std::pair<absl::string_view, absl::string_view> kv =
        absl::StrSplit(lines[k + 1], absl::MaxSplits(' ', 1));
    if (kv.first != kKeys[k]) {
      return absl::InvalidArgumentError(absl::StrCat(
          "line ", line, ": expected '", kKeys[k], "', got '", kv.first, "'"));
    }
    const std::string_view value(kv.second.data(), kv.second.size());
    const std::vector<absl::string_view> words =
        absl::StrSplit(kv.second, ' ', absl::SkipEmpty());
    switch (k) {
      case 0:
        kind = std::string(value);
        break;
      case 1:
        for (absl::string_view w : words) features.emplace_back(w);
        break;
      case 2:
      case 3: {
        FOVEA_ASSIGN_OR_RETURN(double v, ParseNumber(value, line));
        (k == 2 ? gamma : rho) = v;
        break;
      }
      case 4: {
        if (words.size() != 2) {
          return absl::InvalidArgumentError(
              absl::StrCat("line ", line, ": probability needs A and B"));
        }
        absl::StatusOr<double> a = ParseNumber(
            std::string_view(words[0].data(), words[0].size()), line);
        absl::StatusOr<double> b = ParseNumber(
            std::string_view(words[1].data(), words[1].size()), line);
        if (!a.ok()) return a.status();
        if (!b.ok()) return b.status();
        prob_a = *a;
        prob_b = *b;
        break;
      }
      case 5:
        provenance = std::string(value);
        break;
      default: {
        FOVEA_ASSIGN_OR_RETURN(double v, ParseNumber(value, line));
        if (v < 0 || v > kMaxSupportVectors || v != std::floor(v)) {
          return absl::InvalidArgumentError(absl::StrCat(
              "line ", line, ": vectors must be a whole number in [0, ",
              kMaxSupportVectors, "]"));
        }
        count = static_cast<int64_t>(v);
      }
    }
  }
  if (kind != expected_kind) {
    return absl::InvalidArgumentError(absl::StrCat(
        "kind is '", kind, "', expected '", AbslView(expected_kind), "'"));
  }
  if (features.empty()) {
    return absl::InvalidArgumentError("line 3: no features");
  }
  if (!(gamma > 0.0)) {
    return absl::InvalidArgumentError("line 4: gamma must be positive");
  }
  if (static_cast<int64_t>(lines.size()) != 1 + kHeader + count) {
    return absl::InvalidArgumentError(absl::StrCat(
        count, " vectors announced, ",
        static_cast<int64_t>(lines.size()) - 1 - kHeader, " lines follow"));
  }
  std::vector<std::vector<double>> vectors;
  std::vector<double> coefficients;
  for (int64_t i = 0; i < count; ++i) {
    const int line = static_cast<int>(2 + kHeader + i);
    const std::vector<absl::string_view> words =
        absl::StrSplit(lines[1 + kHeader + i], ' ', absl::SkipEmpty());
    if (words.size() != features.size() + 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("line ", line, ": ", words.size(), " numbers, expected ",
                       features.size() + 1));
    }
    std::vector<double> v;
    for (size_t w = 0; w < words.size(); ++w) {
      FOVEA_ASSIGN_OR_RETURN(
          double x,
          ParseNumber(std::string_view(words[w].data(), words[w].size()),
                      line));
      if (w == 0) {
        coefficients.push_back(x);
      } else {
        v.push_back(x);
      }
    }
    vectors.push_back(std::move(v));
  }
  return RbfSvm(std::move(kind), std::move(features), gamma, std::move(vectors),
                std::move(coefficients), rho, prob_a, prob_b,
                std::move(provenance));
}

}  // namespace fovea
