#ifndef FOVEA_CORE_SEGMENTATION_LINEAR_SVM_H_
#define FOVEA_CORE_SEGMENTATION_LINEAR_SVM_H_

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

// A linear SVM, f(x) = w . x + b, accepting x when f(x) > 0: the decision
// of COS's patch growing (thesis section 3.2.2). Trained with libsvm
// (C-SVC, linear kernel); w is read back from its support vectors, so
// applying it needs no libsvm.
class LinearSvm {
 public:
  LinearSvm(std::string kind, std::vector<std::string> feature_names,
            std::vector<double> weights, double bias, std::string provenance);

  // w . x + b; x has feature_names().size() values.
  double Decision(const std::vector<double>& x) const;

  const std::string& kind() const { return kind_; }  // e.g. "cos"
  const std::vector<std::string>& feature_names() const {
    return feature_names_;
  }
  const std::vector<double>& weights() const { return weights_; }
  double bias() const { return bias_; }
  // Free text: the data, command and cross-validated accuracy.
  const std::string& provenance() const { return provenance_; }

  // "<kind>-<16 hex digits of a hash of Serialize()>": changes with any
  // number in the model.
  std::string Version() const;

  // Text, one "key value..." line each:
  //   fovea-linear-svm 1
  //   kind cos
  //   features color_similarity compactness_cm
  //   weights 2.5 -1.25
  //   bias 0.5
  //   provenance trained on ...
  std::string Serialize() const;

  // Reads Serialize()'s text. INVALID_ARGUMENT naming the line for
  // anything else: another magic line or format version, a missing or
  // repeated key, a kind other than `expected_kind`, a weight count other
  // than the feature count, a number that does not parse or is not finite.
  static absl::StatusOr<LinearSvm> Parse(std::string_view text,
                                         std::string_view expected_kind);

 private:
  std::string kind_;
  std::vector<std::string> feature_names_;
  std::vector<double> weights_;
  double bias_ = 0.0;
  std::string provenance_;
};

// One training example: features, class (+1 accept, -1 reject) and the
// group it comes from (the scene), for grouped cross-validation.
struct SvmSample {
  std::vector<double> x;
  int label = 0;
  int group = 0;
};

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_LINEAR_SVM_H_
