#ifndef FOVEA_CORE_SEGMENTATION_SVM_TRAINING_H_
#define FOVEA_CORE_SEGMENTATION_SVM_TRAINING_H_

// Training and cross-validation of the SVMs (libsvm underneath), in the
// fovea_training library: the tools and tests that train link it; the
// server, which only applies trained models (linear_svm.h, rbf_svm.h),
// does not, and so does not link libsvm.

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/rbf_svm.h"

namespace fovea {

struct LinearSvmTrainingOptions {
  // Soft-margin penalty (libsvm -c), > 0.
  double c = 1.0;
  // Weight each class by the inverse of its share, so that the rarer class
  // (accepted patches are the minority) counts as much as the other.
  bool balance_classes = true;
  // libsvm's stopping tolerance (-e), > 0.
  double epsilon = 1e-3;
};

absl::Status Validate(const LinearSvmTrainingOptions& options);

// Trains on every sample. INVALID_ARGUMENT for no samples, one class only,
// samples of different lengths or labels other than +1 / -1.
absl::StatusOr<LinearSvm> TrainLinearSvm(
    const std::vector<SvmSample>& samples,
    const std::vector<std::string>& feature_names, std::string kind,
    const LinearSvmTrainingOptions& options);

struct CrossValidation {
  double accuracy = 0.0;           // correct / samples
  double balanced_accuracy = 0.0;  // mean of the two classes' recalls
  int folds = 0;
  int samples = 0;
};

// k-fold cross-validation by group: group g is in fold g mod k, so a
// scene's samples are never both trained and tested on. Errors as
// TrainLinearSvm's, and for k < 2.
absl::StatusOr<CrossValidation> CrossValidateLinearSvm(
    const std::vector<SvmSample>& samples, int folds,
    const LinearSvmTrainingOptions& options);

struct RbfSvmTrainingOptions {
  // Soft-margin penalty and RBF width, > 0. The thesis found C = 512,
  // gamma = 2 by 10-fold cross-validation; redone on the learn scenes by
  // scene folds (fovea-train inc --grid), C = 32, gamma = 0.5 scores best
  // (balanced accuracy 0.770 against 0.734).
  double c = 32.0;
  double gamma = 0.5;
  bool balance_classes = true;  // weight classes by inverse frequency
  double epsilon = 1e-3;        // libsvm's stopping tolerance, > 0
};

absl::Status Validate(const RbfSvmTrainingOptions& options);

// Trains on every sample (labels +1 / -1) with probability outputs.
// Errors as TrainLinearSvm's.
absl::StatusOr<RbfSvm> TrainRbfSvm(const std::vector<SvmSample>& samples,
                                   const std::vector<std::string>& names,
                                   std::string kind,
                                   const RbfSvmTrainingOptions& options);

// Grouped k-fold cross-validation (group g in fold g mod k), as
// CrossValidateLinearSvm.
absl::StatusOr<CrossValidation> CrossValidateRbfSvm(
    const std::vector<SvmSample>& samples, int folds,
    const RbfSvmTrainingOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_SVM_TRAINING_H_
