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
#include "core/base/strings.h"

extern "C" {
#include "libsvm/svm.h"
}

namespace fovea {
namespace {

constexpr std::string_view kMagic = "fovea-linear-svm 1";
// Longest model text Parse reads, bytes (a model is a few hundred).
constexpr size_t kMaxModelBytes = 1 << 20;

void Quiet(const char*) {}

// FNV-1a, 64 bits: a stable content hash for Version().
uint64_t Fnv1a(std::string_view text) {
  uint64_t hash = 14695981039346656037ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  return hash;
}

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

// libsvm's training on `samples`; w and b read back from the model.
std::pair<std::vector<double>, double> TrainWeights(
    const std::vector<SvmSample>& samples,
    const LinearSvmTrainingOptions& options) {
  const size_t dims = samples[0].x.size();
  // Each sample: dims nodes plus the terminator (index -1).
  std::vector<std::vector<svm_node>> nodes(samples.size());
  std::vector<svm_node*> rows(samples.size());
  std::vector<double> labels(samples.size());
  int positives = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    for (size_t d = 0; d < dims; ++d) {
      nodes[i].push_back({static_cast<int>(d + 1), samples[i].x[d]});
    }
    nodes[i].push_back({-1, 0.0});
    rows[i] = nodes[i].data();
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
  svm_parameter param{};
  param.svm_type = C_SVC;
  param.kernel_type = LINEAR;
  param.cache_size = 100;
  param.eps = options.epsilon;
  param.C = options.c;
  param.shrinking = 1;
  if (options.balance_classes) {
    param.nr_weight = 2;
    param.weight_label = weight_labels;
    param.weight = weights;
  }
  svm_set_print_string_function(&Quiet);
  svm_model* model = svm_train(&problem, &param);
  std::vector<double> w(dims, 0.0);
  for (int i = 0; i < model->l; ++i) {
    for (const svm_node* node = model->SV[i]; node->index != -1; ++node) {
      w[node->index - 1] += model->sv_coef[0][i] * node->value;
    }
  }
  double b = -model->rho[0];
  // libsvm's decision is positive for its first label.
  if (model->label[0] != 1) {
    for (double& v : w) v = -v;
    b = -b;
  }
  svm_free_and_destroy_model(&model);
  return {std::move(w), b};
}

absl::StatusOr<double> ParseNumber(std::string_view text, int line) {
  double value = 0.0;
  if (!absl::SimpleAtod(AbslView(text), &value) || !std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "line ", line, ": '", AbslView(text), "' is not a finite number"));
  }
  return value;
}

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
  return absl::StrFormat("%s-%016x", kind_, Fnv1a(Serialize()));
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
          absl::StatusOr<double> v =
              ParseNumber(std::string_view(w.data(), w.size()), line);
          if (!v.ok()) return v.status();
          weights.push_back(*v);
        }
        break;
      case 3: {
        absl::StatusOr<double> v = ParseNumber(
            std::string_view(kv.second.data(), kv.second.size()), line);
        if (!v.ok()) return v.status();
        bias = *v;
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
  if (absl::Status s = Validate(options); !s.ok()) return s;
  if (absl::Status s = CheckSamples(samples); !s.ok()) return s;
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
  if (folds < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("folds must be at least 2, got ", folds));
  }
  if (absl::Status s = Validate(options); !s.ok()) return s;
  if (absl::Status s = CheckSamples(samples); !s.ok()) return s;
  int correct = 0;
  int tested = 0;
  int true_pos = 0;
  int positives = 0;
  int true_neg = 0;
  int negatives = 0;
  int used_folds = 0;
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<SvmSample> train;
    std::vector<const SvmSample*> test;
    for (const SvmSample& s : samples) {
      if (((s.group % folds) + folds) % folds == fold) {
        test.push_back(&s);
      } else {
        train.push_back(s);
      }
    }
    if (test.empty() || CheckSamples(train) != absl::OkStatus()) continue;
    ++used_folds;
    const auto [w, b] = TrainWeights(train, options);
    const LinearSvm svm("cv", std::vector<std::string>(w.size()), w, b, "");
    for (const SvmSample* s : test) {
      const bool accept = svm.Decision(s->x) > 0.0;
      const bool right = accept == (s->label == 1);
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
  const double pos_recall =
      positives > 0 ? static_cast<double>(true_pos) / positives : 0.0;
  const double neg_recall =
      negatives > 0 ? static_cast<double>(true_neg) / negatives : 0.0;
  cv.balanced_accuracy = 0.5 * (pos_recall + neg_recall);
  return cv;
}

}  // namespace fovea
