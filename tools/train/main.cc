// fovea-train: the trained models of segmentation, from labelled scenes.
//
//   fovea-train cos --data DIR --out models/cos_svm.txt [--folds 5] [--c 1]
//   fovea-train ebs --data DIR --out models/ebs_edges.txt [--folds 5]
//   fovea-train inc --data DIR --out models/inc_relations.txt [--grid]
//                   [--piles N] [--stacked N] [--sensor FAMILY]
//
// Prints the k-fold cross-validated accuracy (folds by scene) and writes
// the model trained on every scene, with that accuracy in its provenance.

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/str_format.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/segment.h"
#include "core/segmentation/cos.h"
#include "core/segmentation/ebs.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/svm_training.h"
#include "core/synth/synth_scene.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/training_scenes.h"

ABSL_FLAG(std::string, data, "",
          "OSD-format folder: *.pcd files, or a folder with learn/ inside. "
          "Defaults to $FOVEA_OSD_DIR.");
ABSL_FLAG(std::string, out, "", "Model file to write.");
ABSL_FLAG(int, folds, 5,
          "Cross-validation folds; scene i is in fold i mod folds.");
ABSL_FLAG(std::string, samples_csv, "",
          "Also write the training samples (features, label, scene) as CSV.");
ABSL_FLAG(bool, grid, false,
          "inc: search C and gamma by cross-validation (2, 32, 512 x 0.5, "
          "2, 8) instead of using the defaults.");
ABSL_FLAG(int, piles, 0,
          "inc: also train on this many synthetic piles (core/synth "
          "GeneratePile), seeds from 1000001 (evaluations use seeds from 1).");
ABSL_FLAG(int, stacked, 0,
          "inc: also train on this many synthetic stacked piles per sensor "
          "(core/synth GenerateStackedPile, Kinect v1 and active stereo).");
ABSL_FLAG(std::string, sensor, "",
          "inc: train the model of this sensor family (kinect_v1, "
          "active_stereo, time_of_flight; models/README.md): the synthetic "
          "piles and stacked "
          "piles are all seen by it. Unset: piles seen by the Kinect v1 and "
          "stacked piles of both sensors.");
ABSL_FLAG(double, c, fovea::LinearSvmTrainingOptions().c,
          "cos: the SVM's soft-margin penalty C.");

namespace fovea {
namespace {

constexpr int kUsageError = 64;
constexpr int kRunError = 1;

std::string DataDir() {
  std::string data = absl::GetFlag(FLAGS_data);
  if (data.empty()) {
    const char* env = std::getenv("FOVEA_OSD_DIR");
    if (env != nullptr) data = env;
  }
  return data;
}

bool WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  return static_cast<bool>(out);
}

// Mean features of each class, for the log: what the SVM separates.
void PrintClassMeans(const std::vector<SvmSample>& samples) {
  const std::vector<std::string>& names = CosFeatureNames();
  for (const int label : {1, -1}) {
    std::vector<double> mean(names.size(), 0.0);
    int n = 0;
    for (const SvmSample& s : samples) {
      if (s.label != label) continue;
      for (size_t i = 0; i < mean.size(); ++i) mean[i] += s.x[i];
      ++n;
    }
    std::printf("  %s: %d samples, mean", label == 1 ? "join" : "reject", n);
    for (size_t i = 0; i < mean.size(); ++i) {
      std::printf(" %s %.3f", names[i].c_str(), n > 0 ? mean[i] / n : 0.0);
    }
    std::printf("\n");
  }
}

// The scenes of --data, or an exit code (after a message) when --data or
// --out is missing or the scenes cannot be read.
int LoadScenesOrExit(const char* command,
                     absl::StatusOr<std::vector<LabelledFrame>>& scenes) {
  const std::string data = DataDir();
  if (data.empty() || absl::GetFlag(FLAGS_out).empty()) {
    std::fprintf(stderr,
                 "fovea-train %s: --data (or FOVEA_OSD_DIR) and --out are "
                 "required\n",
                 command);
    return kUsageError;
  }
  scenes = eval::LoadScenes(data);
  if (!scenes.ok()) {
    std::fprintf(stderr, "fovea-train: %s\n",
                 scenes.status().ToString().c_str());
    return kRunError;
  }
  return 0;
}

// With --samples_csv, the samples as CSV (the features by `names`, then
// label and scene); false after a message when the file cannot be written.
bool WriteSamplesCsv(const std::vector<std::string>& names,
                     const std::vector<SvmSample>& samples) {
  const std::string csv = absl::GetFlag(FLAGS_samples_csv);
  if (csv.empty()) return true;
  std::string text;
  for (const std::string& name : names) text += name + ",";
  text += "label,scene\n";
  for (const SvmSample& s : samples) {
    for (const double x : s.x) text += absl::StrFormat("%.5g,", x);
    text += absl::StrFormat("%d,%d\n", s.label, s.group);
  }
  if (!WriteFile(csv, text)) {
    std::fprintf(stderr, "fovea-train: cannot write %s\n", csv.c_str());
    return false;
  }
  return true;
}

int TrainCos() {
  const std::string out = absl::GetFlag(FLAGS_out);
  absl::StatusOr<std::vector<LabelledFrame>> scenes;
  if (const int code = LoadScenesOrExit("cos", scenes); code != 0) return code;
  const SegmentOptions segment;
  std::vector<SvmSample> samples;
  for (size_t i = 0; i < scenes->size(); ++i) {
    absl::StatusOr<std::vector<SvmSample>> s = CollectCosSamples(
        (*scenes)[i], static_cast<int>(i), segment.detect, segment.cos);
    if (!s.ok()) {
      std::fprintf(stderr, "fovea-train: %s: %s\n", (*scenes)[i].name.c_str(),
                   s.status().ToString().c_str());
      return kRunError;
    }
    samples.insert(samples.end(), s->begin(), s->end());
  }
  std::printf("cos: %zu samples from %zu scenes\n", samples.size(),
              scenes->size());
  PrintClassMeans(samples);
  if (!WriteSamplesCsv(CosFeatureNames(), samples)) return kRunError;
  LinearSvmTrainingOptions svm;
  svm.c = absl::GetFlag(FLAGS_c);
  const int folds = absl::GetFlag(FLAGS_folds);
  absl::StatusOr<CrossValidation> cv =
      CrossValidateLinearSvm(samples, folds, svm);
  if (!cv.ok()) {
    std::fprintf(stderr, "fovea-train: %s\n", cv.status().ToString().c_str());
    return kRunError;
  }
  std::printf("cos: %d-fold cross-validated accuracy %.3f, balanced %.3f\n",
              cv->folds, cv->accuracy, cv->balanced_accuracy);
  absl::StatusOr<LinearSvm> model =
      TrainLinearSvm(samples, CosFeatureNames(), "cos", svm);
  if (!model.ok()) {
    std::fprintf(stderr, "fovea-train: %s\n",
                 model.status().ToString().c_str());
    return kRunError;
  }
  const LinearSvm trained(
      "cos", model->feature_names(), model->weights(), model->bias(),
      absl::StrFormat("fovea-train cos, %zu scenes, %zu samples, C %g; "
                      "%d-fold cross-validated accuracy %.3f (balanced %.3f)",
                      scenes->size(), samples.size(), svm.c, cv->folds,
                      cv->accuracy, cv->balanced_accuracy));
  if (!WriteFile(out, trained.Serialize())) {
    std::fprintf(stderr, "fovea-train: cannot write %s\n", out.c_str());
    return kRunError;
  }
  std::printf("cos: weights");
  for (size_t i = 0; i < trained.weights().size(); ++i) {
    std::printf(" %s %.4f", trained.feature_names()[i].c_str(),
                trained.weights()[i]);
  }
  std::printf(", bias %.4f\nwrote %s (%s)\n", trained.bias(), out.c_str(),
              trained.Version().c_str());
  return 0;
}

int TrainEbs() {
  const std::string out = absl::GetFlag(FLAGS_out);
  absl::StatusOr<std::vector<LabelledFrame>> scenes;
  if (const int code = LoadScenesOrExit("ebs", scenes); code != 0) return code;
  const int folds = absl::GetFlag(FLAGS_folds);
  if (folds < 2) {
    std::fprintf(stderr, "fovea-train: --folds must be at least 2\n");
    return kUsageError;
  }
  const EbsTrainOptions options;
  // Cross-validation by scene: train on the other folds, classify the
  // fold's pixels (edge or not, at p = 0.5).
  int64_t correct = 0;
  int64_t total = 0;
  double balanced = 0.0;
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<const LabelledFrame*> train;
    std::vector<const LabelledFrame*> test;
    for (size_t i = 0; i < scenes->size(); ++i) {
      (static_cast<int>(i) % folds == fold ? test : train)
          .push_back(&(*scenes)[i]);
    }
    absl::StatusOr<EbsModel> model = EbsModel::Train(train, options);
    if (!model.ok()) {
      std::fprintf(stderr, "fovea-train: %s\n",
                   model.status().ToString().c_str());
      return kRunError;
    }
    absl::StatusOr<EbsEvaluation> evaluation = model->Evaluate(test);
    if (!evaluation.ok()) {
      std::fprintf(stderr, "fovea-train: %s\n",
                   evaluation.status().ToString().c_str());
      return kRunError;
    }
    const EdgeCounts& fused = evaluation->fused;
    correct += fused.true_edge + fused.true_no_edge;
    total += fused.true_edge + fused.missed_edge + fused.true_no_edge +
             fused.false_edge;
    balanced += fused.BalancedAccuracy() / folds;
  }
  const double accuracy = total > 0 ? static_cast<double>(correct) / total : 0;
  std::printf(
      "ebs: %d-fold cross-validated edge accuracy %.3f, balanced %.3f\n", folds,
      accuracy, balanced);
  std::vector<const LabelledFrame*> all;
  for (const LabelledFrame& scene : *scenes) all.push_back(&scene);
  absl::StatusOr<EbsModel> model = EbsModel::Train(all, options);
  if (!model.ok()) {
    std::fprintf(stderr, "fovea-train: %s\n",
                 model.status().ToString().c_str());
    return kRunError;
  }
  if (!WriteFile(out, model->Serialize())) {
    std::fprintf(stderr, "fovea-train: cannot write %s\n", out.c_str());
    return kRunError;
  }
  std::printf("wrote %s (%s), trained on %zu scenes\n", out.c_str(),
              model->Version().c_str(), scenes->size());
  return 0;
}

int TrainInc() {
  const std::string out = absl::GetFlag(FLAGS_out);
  absl::StatusOr<std::vector<LabelledFrame>> scenes;
  if (const int code = LoadScenesOrExit("inc", scenes); code != 0) return code;
  const int learn_scenes = static_cast<int>(scenes->size());
  const int piles = absl::GetFlag(FLAGS_piles);
  if (piles < 0) {
    std::fprintf(stderr, "fovea-train: --piles must not be negative\n");
    return kUsageError;
  }
  const int stacked = absl::GetFlag(FLAGS_stacked);
  if (stacked < 0) {
    std::fprintf(stderr, "fovea-train: --stacked must not be negative\n");
    return kUsageError;
  }
  const std::string sensor_name = absl::GetFlag(FLAGS_sensor);
  std::vector<LabelledFrame> synthetic;
  if (sensor_name.empty()) {
    synthetic = eval::SyntheticTrainingScenes(piles, stacked);
  } else {
    absl::StatusOr<synth::RoomSensor> sensor =
        synth::ParseRoomSensor(sensor_name);
    if (!sensor.ok()) {
      std::fprintf(stderr, "fovea-train: --sensor: %s\n",
                   std::string(sensor.status().message()).c_str());
      return kUsageError;
    }
    synthetic = eval::SyntheticTrainingScenes(piles, stacked, *sensor);
  }
  for (LabelledFrame& scene : synthetic) scenes->push_back(std::move(scene));
  const IncrementalOptions options;
  std::vector<SvmSample> samples;
  for (size_t i = 0; i < scenes->size(); ++i) {
    absl::StatusOr<std::vector<SvmSample>> s = CollectIncSamples(
        (*scenes)[i], static_cast<int>(i), options.detect, options.inc);
    if (!s.ok()) {
      std::fprintf(stderr, "fovea-train: %s: %s\n", (*scenes)[i].name.c_str(),
                   s.status().ToString().c_str());
      return kRunError;
    }
    samples.insert(samples.end(), s->begin(), s->end());
  }
  int positives = 0;
  for (const SvmSample& s : samples) positives += s.label == 1 ? 1 : 0;
  std::printf("inc: %zu relation samples from %zu scenes (%d same object)\n",
              samples.size(), scenes->size(), positives);
  if (!WriteSamplesCsv(RelationFeatureNames(), samples)) return kRunError;
  const int folds = absl::GetFlag(FLAGS_folds);
  // The thesis's search (10-fold, C and gamma on a log2 grid) redone by
  // scene folds on a coarser grid; without --grid, the defaults (the
  // grid's winner on the learn scenes).
  const RbfSvmTrainingOptions defaults;
  std::vector<std::pair<double, double>> grid = {{defaults.c, defaults.gamma}};
  if (absl::GetFlag(FLAGS_grid)) {
    grid.clear();
    for (const double c : {2.0, 32.0, 512.0}) {
      for (const double gamma : {0.5, 2.0, 8.0}) grid.emplace_back(c, gamma);
    }
  }
  RbfSvmTrainingOptions best;
  double best_accuracy = -1.0;
  CrossValidation best_cv;
  for (const auto& [c, gamma] : grid) {
    RbfSvmTrainingOptions svm;
    svm.c = c;
    svm.gamma = gamma;
    absl::StatusOr<CrossValidation> cv =
        CrossValidateRbfSvm(samples, folds, svm);
    if (!cv.ok()) {
      std::fprintf(stderr, "fovea-train: %s\n", cv.status().ToString().c_str());
      return kRunError;
    }
    std::printf(
        "inc: C %g gamma %g: %d-fold cross-validated accuracy %.3f, "
        "balanced %.3f\n",
        c, gamma, cv->folds, cv->accuracy, cv->balanced_accuracy);
    if (cv->balanced_accuracy > best_accuracy) {
      best_accuracy = cv->balanced_accuracy;
      best = svm;
      best_cv = *cv;
    }
  }
  absl::StatusOr<RbfSvm> model =
      TrainRbfSvm(samples, RelationFeatureNames(), "inc", best);
  if (!model.ok()) {
    std::fprintf(stderr, "fovea-train: %s\n",
                 model.status().ToString().c_str());
    return kRunError;
  }
  const RbfSvm trained = *RbfSvm::Parse(
      model->Serialize(), "inc");  // round trip: what the server will load
  std::string text = trained.Serialize();
  const std::string provenance = absl::StrFormat(
      "fovea-train inc, %d scenes, %d synthetic piles and %d stacked piles "
      "%s (seeds from %u), %zu samples, C %g gamma %g; %d-fold "
      "cross-validated accuracy %.3f (balanced %.3f)",
      learn_scenes, piles, stacked,
      sensor_name.empty() ? "per sensor" : ("seen by " + sensor_name).c_str(),
      static_cast<unsigned>(eval::kTrainingSceneSeed), samples.size(), best.c,
      best.gamma, best_cv.folds, best_cv.accuracy, best_cv.balanced_accuracy);
  const size_t at = text.find("\nprovenance ");
  const size_t end = text.find('\n', at + 1);
  text.replace(at + 12, end - at - 12, provenance);
  if (!WriteFile(out, text)) {
    std::fprintf(stderr, "fovea-train: cannot write %s\n", out.c_str());
    return kRunError;
  }
  std::printf("wrote %s (%s, %zu support vectors)\n", out.c_str(),
              RbfSvm::Parse(text, "inc")->Version().c_str(),
              trained.support_vector_count());
  return 0;
}

}  // namespace
}  // namespace fovea

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(
      "Trains segmentation models on labelled OSD scenes.\n"
      "  fovea-train cos --data DIR --out FILE [--folds 5] [--c 1]\n"
      "  fovea-train ebs --data DIR --out FILE [--folds 5]\n"
      "  fovea-train inc --data DIR --out FILE [--folds 5] [--grid]");
  std::vector<char*> args = absl::ParseCommandLine(argc, argv);
  if (args.size() < 2) {
    std::fprintf(stderr, "%s\n",
                 std::string(absl::ProgramUsageMessage()).c_str());
    return fovea::kUsageError;
  }
  const std::string command = args[1];
  if (command == "cos") return fovea::TrainCos();
  if (command == "ebs") return fovea::TrainEbs();
  if (command == "inc") return fovea::TrainInc();
  std::fprintf(stderr, "fovea-train: unknown command '%s'\n%s\n",
               command.c_str(),
               std::string(absl::ProgramUsageMessage()).c_str());
  return fovea::kUsageError;
}
