// TrainLinearSvm and CrossValidateLinearSvm (svm_training.h).

#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/segmentation/svm_train_common.h"
#include "core/segmentation/svm_training.h"

extern "C" {
#include "libsvm/svm.h"
}

namespace fovea {
namespace {

using svm_internal::CheckSamples;

// libsvm's training on `samples`; w and b read back from the model.
std::pair<std::vector<double>, double> TrainWeights(
    const std::vector<SvmSample>& samples,
    const LinearSvmTrainingOptions& options) {
  svm_parameter param{};
  param.kernel_type = LINEAR;
  param.cache_size = 100;
  param.eps = options.epsilon;
  param.C = options.c;
  param.shrinking = 1;
  const std::unique_ptr<svm_internal::TrainedModel> trained =
      svm_internal::Train(samples, param, options.balance_classes);
  const svm_model& model = *trained->model;
  std::vector<double> w(samples[0].x.size(), 0.0);
  for (int i = 0; i < model.l; ++i) {
    for (const svm_node* node = model.SV[i]; node->index != -1; ++node) {
      w[node->index - 1] += model.sv_coef[0][i] * node->value;
    }
  }
  // libsvm's decision is positive for its first label.
  const double sign = svm_internal::PositiveSign(model);
  for (double& v : w) v *= sign;
  return {std::move(w), -model.rho[0] * sign};
}

}  // namespace

absl::Status Validate(const LinearSvmTrainingOptions& options) {
  if (!(options.c > 0.0) || !std::isfinite(options.c)) {
    return absl::InvalidArgumentError(
        absl::StrCat("c must be positive, got ", options.c));
  }
  if (!(options.epsilon > 0.0) || !std::isfinite(options.epsilon)) {
    return absl::InvalidArgumentError(
        absl::StrCat("epsilon must be positive, got ", options.epsilon));
  }
  return absl::OkStatus();
}

absl::StatusOr<LinearSvm> TrainLinearSvm(
    const std::vector<SvmSample>& samples,
    const std::vector<std::string>& feature_names, std::string kind,
    const LinearSvmTrainingOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_RETURN_IF_ERROR(CheckSamples(samples));
  if (feature_names.size() != samples[0].x.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(feature_names.size(), " feature names for samples of ",
                     samples[0].x.size(), " values"));
  }
  auto [w, b] = TrainWeights(samples, options);
  return LinearSvm(std::move(kind), feature_names, std::move(w), b, "");
}

absl::StatusOr<CrossValidation> CrossValidateLinearSvm(
    const std::vector<SvmSample>& samples, int folds,
    const LinearSvmTrainingOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  return svm_internal::CrossValidate(
      samples, folds, [&options](const std::vector<SvmSample>& training) {
        auto [w, b] = TrainWeights(training, options);
        const LinearSvm svm("cv", std::vector<std::string>(w.size()),
                            std::move(w), b, "");
        return svm_internal::DecisionFunction(
            [svm](const std::vector<double>& x) { return svm.Decision(x); });
      });
}

}  // namespace fovea
