#ifndef FOVEA_CORE_SEGMENTATION_SVM_TRAIN_COMMON_H_
#define FOVEA_CORE_SEGMENTATION_SVM_TRAIN_COMMON_H_

// What the training of LinearSvm and RbfSvm shares: sample checks, libsvm
// problems and grouped cross-validation (fovea_training).

#include <functional>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/segmentation/svm_training.h"

struct svm_model;
struct svm_node;
struct svm_parameter;

namespace fovea::svm_internal {

// OK when there are samples of equal length, labels +1 / -1, both classes.
absl::Status CheckSamples(const std::vector<SvmSample>& samples);

// A libsvm model trained on `samples` with `param` (C_SVC; its class
// weights are set here when `balance_classes`); freed on destruction.
// libsvm's console output is silenced.
struct TrainedModel {
  svm_model* model = nullptr;
  std::vector<std::vector<svm_node>> nodes;  // the problem it points into
  ~TrainedModel();
};
std::unique_ptr<TrainedModel> Train(const std::vector<SvmSample>& samples,
                                    svm_parameter param, bool balance_classes);

// Sign that makes libsvm's decision positive for label +1.
double PositiveSign(const svm_model& model);

// Grouped k-fold cross-validation: `train` returns a decision function for
// the training folds; the fold's samples are classified by its sign.
using DecisionFunction = std::function<double(const std::vector<double>&)>;
absl::StatusOr<CrossValidation> CrossValidate(
    const std::vector<SvmSample>& samples, int folds,
    const std::function<DecisionFunction(const std::vector<SvmSample>&)>&
        train);

}  // namespace fovea::svm_internal

#endif  // FOVEA_CORE_SEGMENTATION_SVM_TRAIN_COMMON_H_
