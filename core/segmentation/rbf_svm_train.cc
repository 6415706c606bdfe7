// TrainRbfSvm and CrossValidateRbfSvm (svm_training.h).

#include <cmath>
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
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_RETURN_IF_ERROR(svm_internal::CheckSamples(samples));
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
  FOVEA_RETURN_IF_ERROR(Validate(options));
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
