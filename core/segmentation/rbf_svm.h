#ifndef FOVEA_CORE_SEGMENTATION_RBF_SVM_H_
#define FOVEA_CORE_SEGMENTATION_RBF_SVM_H_

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/segmentation/linear_svm.h"

namespace fovea {

// An RBF-kernel SVM with Platt-scaled probabilities (libsvm's C-SVC with
// -b 1): f(x) = sum_i coef_i exp(-gamma |x - sv_i|^2) - rho and
// p(+1 | x) = 1 / (1 + exp(A f(x) + B)). Trained with libsvm; applying it
// needs no libsvm. INC's relation classifier (thesis section 3.3.2).
class RbfSvm {
 public:
  RbfSvm(std::string kind, std::vector<std::string> feature_names, double gamma,
         std::vector<std::vector<double>> support_vectors,
         std::vector<double> coefficients, double rho, double prob_a,
         double prob_b, std::string provenance);

  double Decision(const std::vector<double>& x) const;
  // p(+1 | x), in [0, 1].
  double Probability(const std::vector<double>& x) const;

  const std::string& kind() const { return kind_; }
  const std::vector<std::string>& feature_names() const {
    return feature_names_;
  }
  double gamma() const { return gamma_; }
  size_t support_vector_count() const { return support_vectors_.size(); }
  const std::string& provenance() const { return provenance_; }

  // "<kind>-<16 hex digits of a hash of Serialize()>".
  std::string Version() const;
  // Text: "fovea-rbf-svm 1", then "kind", "features", "gamma", "rho",
  // "probability A B", "provenance" lines, "vectors N", and N lines
  // "coefficient x1 ... xd".
  std::string Serialize() const;
  // INVALID_ARGUMENT naming the line for anything else (wrong magic or
  // version, kind other than `expected_kind`, a count that does not match,
  // a number that does not parse or is not finite, more than 1 MiB... of
  // vectors than kMaxSupportVectors).
  static absl::StatusOr<RbfSvm> Parse(std::string_view text,
                                      std::string_view expected_kind);

 private:
  std::string kind_;
  std::vector<std::string> feature_names_;
  double gamma_ = 1.0;
  std::vector<std::vector<double>> support_vectors_;
  std::vector<double> coefficients_;
  double rho_ = 0.0;
  double prob_a_ = 0.0;
  double prob_b_ = 0.0;
  std::string provenance_;
};

// Most support vectors a model file may hold.
inline constexpr int kMaxSupportVectors = 200000;

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_RBF_SVM_H_
