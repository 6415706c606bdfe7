#include "core/segmentation/rbf_svm.h"

#include <cmath>
#include <cstdlib>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "core/base/strings.h"
#include "core/segmentation/svm_common.h"

extern "C" {
#include "libsvm/svm.h"
}

namespace fovea {
namespace {

using svm_internal::ParseNumber;

constexpr std::string_view kMagic = "fovea-rbf-svm 1";

std::string Number(double v) { return absl::StrFormat("%.17g", v); }

// libsvm RBF + probability training, read back into an RbfSvm.
RbfSvm TrainModel(const std::vector<SvmSample>& samples,
                  const std::vector<std::string>& names, std::string kind,
                  const RbfSvmTrainingOptions& options) {
  svm_parameter param{};
  param.kernel_type = RBF;
  param.gamma = options.gamma;
  param.cache_size = 200;
  param.eps = options.epsilon;
  param.C = options.c;
  param.shrinking = 1;
  param.probability = 1;
  // libsvm's Platt scaling shuffles its internal folds with rand(): seeded
  // here, a model depends on its samples and options only, not on what
  // trained before it in the process (fovea-train --grid or not). Training
  // is offline and single-threaded.
  std::srand(1);
  const std::unique_ptr<svm_internal::TrainedModel> trained =
      svm_internal::Train(samples, param, options.balance_classes);
  const svm_model& model = *trained->model;
  const double sign = svm_internal::PositiveSign(model);
  const size_t dims = samples[0].x.size();
  std::vector<std::vector<double>> vectors;
  std::vector<double> coefficients;
  for (int i = 0; i < model.l; ++i) {
    std::vector<double> v(dims, 0.0);
    for (const svm_node* node = model.SV[i]; node->index != -1; ++node) {
      v[node->index - 1] = node->value;
    }
    vectors.push_back(std::move(v));
    coefficients.push_back(sign * model.sv_coef[0][i]);
  }
  // libsvm: p(label[0] | x) = 1 / (1 + exp(A f0 + B)) with f0 its own
  // decision; ours is f = sign * f0, so p(+1) has A' = A * sign when
  // label[0] is +1, and p(+1) = 1 - p(label[0]) = 1 / (1 + exp(-A f0 - B))
  // otherwise: A' = A, B' = -B with f = -f0.
  const double a = model.probA[0];
  const double b = model.probB[0];
  const double prob_a = a;
  const double prob_b = sign > 0 ? b : -b;
  return RbfSvm(std::move(kind), names, options.gamma, std::move(vectors),
                std::move(coefficients), sign * model.rho[0], prob_a, prob_b,
                "");
}

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
        absl::StatusOr<double> v = ParseNumber(value, line);
        if (!v.ok()) return v.status();
        (k == 2 ? gamma : rho) = *v;
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
        absl::StatusOr<double> v = ParseNumber(value, line);
        if (!v.ok()) return v.status();
        if (*v < 0 || *v > kMaxSupportVectors || *v != std::floor(*v)) {
          return absl::InvalidArgumentError(absl::StrCat(
              "line ", line, ": vectors must be a whole number in [0, ",
              kMaxSupportVectors, "]"));
        }
        count = static_cast<int64_t>(*v);
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
      absl::StatusOr<double> x =
          ParseNumber(std::string_view(words[w].data(), words[w].size()), line);
      if (!x.ok()) return x.status();
      if (w == 0) {
        coefficients.push_back(*x);
      } else {
        v.push_back(*x);
      }
    }
    vectors.push_back(std::move(v));
  }
  return RbfSvm(std::move(kind), std::move(features), gamma, std::move(vectors),
                std::move(coefficients), rho, prob_a, prob_b,
                std::move(provenance));
}

absl::Status Validate(const RbfSvmTrainingOptions& options) {
  if (!(options.c > 0.0) || !std::isfinite(options.c)) {
    return absl::InvalidArgumentError(
        absl::StrCat("c must be positive, got ", options.c));
  }
  if (!(options.gamma > 0.0) || !std::isfinite(options.gamma)) {
    return absl::InvalidArgumentError(
        absl::StrCat("gamma must be positive, got ", options.gamma));
  }
  if (!(options.epsilon > 0.0) || !std::isfinite(options.epsilon)) {
    return absl::InvalidArgumentError(
        absl::StrCat("epsilon must be positive, got ", options.epsilon));
  }
  return absl::OkStatus();
}

absl::StatusOr<RbfSvm> TrainRbfSvm(const std::vector<SvmSample>& samples,
                                   const std::vector<std::string>& names,
                                   std::string kind,
                                   const RbfSvmTrainingOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  if (absl::Status s = svm_internal::CheckSamples(samples); !s.ok()) return s;
  if (names.size() != samples[0].x.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(names.size(), " feature names for samples of ",
                     samples[0].x.size(), " values"));
  }
  return TrainModel(samples, names, std::move(kind), options);
}

absl::StatusOr<CrossValidation> CrossValidateRbfSvm(
    const std::vector<SvmSample>& samples, int folds,
    const RbfSvmTrainingOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  return svm_internal::CrossValidate(
      samples, folds, [&options](const std::vector<SvmSample>& training) {
        const RbfSvm svm =
            TrainModel(training, std::vector<std::string>(training[0].x.size()),
                       "cv", options);
        return svm_internal::DecisionFunction(
            [svm](const std::vector<double>& x) { return svm.Decision(x); });
      });
}

}  // namespace fovea
