#include "core/segmentation/svm_train_common.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

extern "C" {
#include "libsvm/svm.h"
}

namespace fovea::svm_internal {
namespace {

void Quiet(const char*) {}

}  // namespace

absl::Status CheckSamples(const std::vector<SvmSample>& samples) {
  if (samples.empty()) return absl::InvalidArgumentError("no samples");
  bool positive = false;
  bool negative = false;
  for (const SvmSample& s : samples) {
    if (s.x.size() != samples[0].x.size()) {
      return absl::InvalidArgumentError("samples have different lengths");
    }
    if (s.label != 1 && s.label != -1) {
      return absl::InvalidArgumentError(
          absl::StrCat("sample label must be +1 or -1, got ", s.label));
    }
    positive |= s.label == 1;
    negative |= s.label == -1;
  }
  if (!positive || !negative) {
    return absl::InvalidArgumentError(
        "samples of both classes (+1 and -1) are needed");
  }
  return absl::OkStatus();
}

TrainedModel::~TrainedModel() {
  if (model != nullptr) svm_free_and_destroy_model(&model);
}

std::unique_ptr<TrainedModel> Train(const std::vector<SvmSample>& samples,
                                    svm_parameter param, bool balance_classes) {
  auto trained = std::make_unique<TrainedModel>();
  const size_t dims = samples[0].x.size();
  trained->nodes.resize(samples.size());
  std::vector<svm_node*> rows(samples.size());
  std::vector<double> labels(samples.size());
  int positives = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    for (size_t d = 0; d < dims; ++d) {
      trained->nodes[i].push_back({static_cast<int>(d + 1), samples[i].x[d]});
    }
    trained->nodes[i].push_back({-1, 0.0});
    rows[i] = trained->nodes[i].data();
    labels[i] = samples[i].label;
    positives += samples[i].label == 1 ? 1 : 0;
  }
  svm_problem problem{};
  problem.l = static_cast<int>(samples.size());
  problem.y = labels.data();
  problem.x = rows.data();
  int weight_labels[2] = {1, -1};
  const double n = static_cast<double>(samples.size());
  double weights[2] = {n / (2.0 * positives), n / (2.0 * (n - positives))};
  param.svm_type = C_SVC;
  if (balance_classes) {
    param.nr_weight = 2;
    param.weight_label = weight_labels;
    param.weight = weights;
  } else {
    param.nr_weight = 0;
  }
  svm_set_print_string_function(&Quiet);
  // The model keeps pointers to support vectors in `nodes` (libsvm does
  // not copy them), so `trained` owns both.
  trained->model = svm_train(&problem, &param);
  trained->model->param.weight_label = nullptr;
  trained->model->param.weight = nullptr;
  trained->model->param.nr_weight = 0;
  return trained;
}

double PositiveSign(const svm_model& model) {
  return model.label[0] == 1 ? 1.0 : -1.0;
}

absl::StatusOr<CrossValidation> CrossValidate(
    const std::vector<SvmSample>& samples, int folds,
    const std::function<DecisionFunction(const std::vector<SvmSample>&)>&
        train) {
  if (folds < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("folds must be at least 2, got ", folds));
  }
  FOVEA_RETURN_IF_ERROR(CheckSamples(samples));
  int correct = 0, tested = 0, true_pos = 0, positives = 0, true_neg = 0,
      negatives = 0, used_folds = 0;
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<SvmSample> training;
    std::vector<const SvmSample*> test;
    for (const SvmSample& s : samples) {
      if (((s.group % folds) + folds) % folds == fold) {
        test.push_back(&s);
      } else {
        training.push_back(s);
      }
    }
    if (test.empty() || !CheckSamples(training).ok()) continue;
    ++used_folds;
    const DecisionFunction decide = train(training);
    for (const SvmSample* s : test) {
      const bool right = (decide(s->x) > 0.0) == (s->label == 1);
      correct += right ? 1 : 0;
      ++tested;
      if (s->label == 1) {
        ++positives;
        true_pos += right ? 1 : 0;
      } else {
        ++negatives;
        true_neg += right ? 1 : 0;
      }
    }
  }
  if (tested == 0) {
    return absl::InvalidArgumentError(
        "no fold had both a test set and two training classes");
  }
  CrossValidation cv;
  cv.folds = used_folds;
  cv.samples = tested;
  cv.accuracy = static_cast<double>(correct) / tested;
  const double pos =
      positives > 0 ? static_cast<double>(true_pos) / positives : 0.0;
  const double neg =
      negatives > 0 ? static_cast<double>(true_neg) / negatives : 0.0;
  cv.balanced_accuracy = 0.5 * (pos + neg);
  return cv;
}

}  // namespace fovea::svm_internal
