#include "tools/eval/methods_eval.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/segment.h"
#include "core/segmentation/ebs.h"
#include "core/segmentation/relations.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

constexpr double kOverlayAlpha = 0.55;

void WritePng(const std::string& dir, const LabelledFrame& scene,
              SceneMethod method, const SceneRun& run) {
  cv::Mat bgr;
  cv::cvtColor(scene.frame.color, bgr, cv::COLOR_RGB2BGR);
  cv::Mat overlay = bgr.clone();
  for (size_t i = 0; i < run.masks.size(); ++i) {
    overlay.setTo(MaskColor(i), run.masks[i].mask);
  }
  cv::addWeighted(overlay, kOverlayAlpha, bgr, 1.0 - kOverlayAlpha, 0.0,
                  overlay);
  for (size_t i = 0; i < run.masks.size(); ++i) {
    cv::putText(overlay, std::to_string(i + 1), run.masks[i].seed,
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  }
  cv::Mat objects;
  ObjectIdImage(scene.labels).convertTo(objects, CV_8U, 20);
  cv::Mat edges;
  cv::Canny(objects, edges, 1, 1);
  cv::Mat truth = bgr.clone();
  truth.setTo(cv::Scalar(0, 255, 0), edges);
  cv::Mat both;
  cv::hconcat(overlay, truth, both);
  cv::imwrite(
      (std::filesystem::path(dir) /
       absl::StrCat(scene.name, "_", AbslView(SceneMethodName(method)), ".png"))
          .string(),
      both);
}

// Models trained on the scenes of `train` (indices into `scenes`) for the
// methods that need them.
struct FoldModels {
  std::optional<LinearSvm> cos;
  std::optional<EbsModel> ebs;
  std::optional<RbfSvm> inc;
  SegmentModels View() const {
    SegmentModels m;
    m.cos = cos ? &*cos : nullptr;
    m.ebs = ebs ? &*ebs : nullptr;
    m.inc = inc ? &*inc : nullptr;
    return m;
  }
};

bool Uses(const MethodsEvalOptions& o, SceneMethod m) {
  for (const SceneMethod x : o.methods) {
    if (x == m) return true;
  }
  return false;
}

}  // namespace

absl::StatusOr<MethodResults> EvaluateMethods(
    const std::vector<LabelledFrame>& scenes,
    const MethodsEvalOptions& options) {
  if (options.methods.empty()) {
    return absl::InvalidArgumentError("methods: none given");
  }
  const bool cross_validate = options.folds >= 2;
  if (!cross_validate && options.models == nullptr) {
    return absl::FailedPreconditionError("no models and no cross-validation");
  }
  if (!options.out_dir.empty())
    std::filesystem::create_directories(options.out_dir);

  // Training examples of every scene, once (cross-validation only).
  std::vector<std::vector<SvmSample>> cos_samples(scenes.size());
  std::vector<std::vector<SvmSample>> inc_samples(scenes.size());
  if (cross_validate) {
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (Uses(options, SceneMethod::kCos)) {
        absl::StatusOr<std::vector<SvmSample>> s = CollectCosSamples(
            scenes[i], static_cast<int>(i), options.detect, CosOptions{});
        if (!s.ok()) return InScene(scenes[i].name, s.status());
        cos_samples[i] = *std::move(s);
      }
      if (Uses(options, SceneMethod::kInc)) {
        absl::StatusOr<std::vector<SvmSample>> s = CollectIncSamples(
            scenes[i], static_cast<int>(i), options.detect, IncOptions{});
        if (!s.ok()) return InScene(scenes[i].name, s.status());
        inc_samples[i] = *std::move(s);
      }
    }
  }

  MethodResults results;
  const int folds = cross_validate ? options.folds : 1;
  for (int fold = 0; fold < folds; ++fold) {
    FoldModels trained;
    SegmentModels models;
    if (cross_validate) {
      std::vector<SvmSample> cos_train, inc_train;
      std::vector<const LabelledFrame*> frames;
      for (size_t i = 0; i < scenes.size(); ++i) {
        if (static_cast<int>(i) % folds == fold) continue;
        cos_train.insert(cos_train.end(), cos_samples[i].begin(),
                         cos_samples[i].end());
        inc_train.insert(inc_train.end(), inc_samples[i].begin(),
                         inc_samples[i].end());
        frames.push_back(&scenes[i]);
      }
      if (Uses(options, SceneMethod::kCos)) {
        FOVEA_ASSIGN_OR_RETURN(
            LinearSvm svm, TrainLinearSvm(cos_train, CosFeatureNames(), "cos",
                                          options.cos_svm));
        trained.cos = std::move(svm);
      }
      if (Uses(options, SceneMethod::kEbs)) {
        FOVEA_ASSIGN_OR_RETURN(EbsModel ebs,
                               EbsModel::Train(frames, EbsTrainOptions{}));
        trained.ebs = std::move(ebs);
      }
      if (Uses(options, SceneMethod::kInc)) {
        FOVEA_ASSIGN_OR_RETURN(
            RbfSvm svm, TrainRbfSvm(inc_train, RelationFeatureNames(), "inc",
                                    options.inc_svm));
        trained.inc = std::move(svm);
      }
      models = trained.View();
    } else {
      models = options.models->View();
    }
    for (size_t i = fold; i < scenes.size(); i += folds) {
      const LabelledFrame& scene = scenes[i];
      const int min_pixels =
          std::max(1, static_cast<int>(kEvalMinObjectPixels *
                                       scene.labels.total() / (640.0 * 480.0)));
      const cv::Mat ids = ObjectIdImage(scene.labels);
      for (const SceneMethod method : options.methods) {
        SceneRunOptions run_options;
        run_options.method = method;
        run_options.detect = options.detect;
        run_options.models = models;
        run_options.cover_scene = options.cover_scene;
        absl::StatusOr<SceneRun> run = RunOnScene(scene, run_options);
        if (!run.ok()) {
          return InScene(absl::StrCat(scene.name, " (",
                                      AbslView(SceneMethodName(method)), ")"),
                         run.status());
        }
        MethodSceneResult r;
        r.name = scene.name;
        r.kind = SceneKind(scene.name);
        r.seeded = ScoreSegmentation(scene.labels, run->masks, min_pixels);
        r.whole_scene_f = WholeSceneF(scene.labels, run->segments, min_pixels);
        r.uois = ScoreUois(ids, run->segments, min_pixels);
        r.first_ms = run->first_ms;
        r.total_ms = run->total_ms;
        if (options.verbose) {
          std::fprintf(
              stderr,
              "%-10s %-13s objects %2d/%2d masks %2d  F all %.3f  "
              "whole F %.3f  overlap F %.3f  boundary F %.3f  %.0f ms\n",
              r.name.c_str(), std::string(SceneMethodName(method)).c_str(),
              r.seeded.objects_with_mask, r.seeded.objects, r.seeded.masks,
              r.seeded.f_all, r.whole_scene_f, r.uois.overlap_f,
              r.uois.boundary_f, r.total_ms);
        }
        if (!options.out_dir.empty())
          WritePng(options.out_dir, scene, method, *run);
        results[method].push_back(std::move(r));
      }
    }
  }
  return results;
}

MethodSummary SummarizeMethod(SceneMethod method,
                              const std::vector<MethodSceneResult>& results,
                              const std::string& kind) {
  MethodSummary s;
  s.method = std::string(SceneMethodName(method));
  s.kind = kind;
  int scored = 0, objects = 0, with_mask = 0, masks = 0, false_masks = 0;
  std::vector<double> first, total;
  for (const MethodSceneResult& r : results) {
    if (!kind.empty() && r.kind != kind) continue;
    ++s.scenes;
    objects += r.seeded.objects;
    with_mask += r.seeded.objects_with_mask;
    masks += r.seeded.masks;
    false_masks += r.seeded.false_masks;
    s.whole_scene_f += r.whole_scene_f;
    s.overlap_p += r.uois.overlap_p;
    s.overlap_r += r.uois.overlap_r;
    s.overlap_f += r.uois.overlap_f;
    s.boundary_p += r.uois.boundary_p;
    s.boundary_r += r.uois.boundary_r;
    s.boundary_f += r.uois.boundary_f;
    s.objects_075 += r.uois.objects_075;
    first.push_back(r.first_ms);
    total.push_back(r.total_ms);
    if (r.seeded.objects_with_mask == 0) continue;
    ++scored;
    s.f_all += r.seeded.f_all;
    s.f_best += r.seeded.f_best;
    s.f_first += r.seeded.f_first;
  }
  if (scored > 0) {
    s.f_all /= scored;
    s.f_best /= scored;
    s.f_first /= scored;
  }
  if (s.scenes > 0) {
    const double n = s.scenes;
    for (double* x :
         {&s.whole_scene_f, &s.overlap_p, &s.overlap_r, &s.overlap_f,
          &s.boundary_p, &s.boundary_r, &s.boundary_f, &s.objects_075}) {
      *x /= n;
    }
  }
  s.object_recall =
      objects > 0 ? static_cast<double>(with_mask) / objects : 0.0;
  s.false_masks = masks > 0 ? static_cast<double>(false_masks) / masks : 0.0;
  s.first_ms_median = Median(first);
  s.total_ms_median = Median(total);
  return s;
}

}  // namespace fovea::eval
