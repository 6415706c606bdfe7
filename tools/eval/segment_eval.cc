#include "tools/eval/segment_eval.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

// Objects smaller than this are not counted: slivers seen through a gap.
constexpr int kMinObjectPixels = 50;
constexpr double kOverlayAlpha = 0.55;

// Colour image with each mask tinted and its seed numbered (emission
// order), beside the ground truth's object outlines.
void WriteMasksPng(const std::string& out_dir, const LabelledFrame& scene,
                   const std::vector<SeededMask>& masks) {
  cv::Mat bgr;
  cv::cvtColor(scene.frame.color, bgr, cv::COLOR_RGB2BGR);
  cv::Mat overlay = bgr.clone();
  for (size_t i = 0; i < masks.size(); ++i) {
    const cv::Scalar color((i * 67) % 256, (80 + i * 151) % 256,
                           (160 + i * 97) % 256);
    overlay.setTo(color, masks[i].mask);
  }
  cv::Mat out;
  cv::addWeighted(overlay, kOverlayAlpha, bgr, 1.0 - kOverlayAlpha, 0.0, out);
  for (size_t i = 0; i < masks.size(); ++i) {
    cv::circle(out, masks[i].seed, 4, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::putText(out, std::to_string(i + 1), masks[i].seed + cv::Point(6, -6),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  }
  cv::Mat objects(scene.labels.size(), CV_8UC1);
  for (int v = 0; v < objects.rows; ++v) {
    for (int u = 0; u < objects.cols; ++u) {
      objects.at<unsigned char>(v, u) =
          static_cast<unsigned char>(ObjectId(scene.labels.at<int>(v, u)) * 20);
    }
  }
  cv::Mat edges;
  cv::Canny(objects, edges, 1, 1);
  cv::Mat truth = bgr.clone();
  truth.setTo(cv::Scalar(0, 255, 0), edges);
  cv::Mat both;
  cv::hconcat(out, truth, both);
  cv::imwrite(
      (std::filesystem::path(out_dir) / (scene.name + "_masks.png")).string(),
      both);
}

}  // namespace

SegmentEvalSummary SummarizeSegment(
    const std::vector<SceneSegmentResult>& scenes, const std::string& kind) {
  SegmentEvalSummary s;
  int scored = 0;
  int objects = 0;
  int with_mask = 0;
  int masks = 0;
  int false_masks = 0;
  std::vector<double> first_ms;
  std::vector<double> all_ms;
  for (const SceneSegmentResult& r : scenes) {
    if (!kind.empty() && r.kind != kind) continue;
    s.scenes.push_back(r);
    objects += r.score.objects;
    with_mask += r.score.objects_with_mask;
    masks += r.score.masks;
    false_masks += r.score.false_masks;
    all_ms.push_back(r.all_masks_ms);
    s.whole_scene_f += r.whole_scene_f;
    if (r.score.masks > 0) first_ms.push_back(r.first_mask_ms);
    if (r.score.objects_with_mask == 0) continue;
    ++scored;
    s.f_all += r.score.f_all;
    s.f_best += r.score.f_best;
    s.f_first += r.score.f_first;
  }
  if (scored > 0) {
    s.f_all /= scored;
    s.f_best /= scored;
    s.f_first /= scored;
  }
  if (!s.scenes.empty())
    s.whole_scene_f /= static_cast<double>(s.scenes.size());
  s.object_recall = objects > 0 ? static_cast<double>(with_mask) / objects : 0;
  s.false_masks = masks > 0 ? static_cast<double>(false_masks) / masks : 0;
  s.first_mask_ms_median = Median(first_ms);
  s.all_masks_ms_median = Median(all_ms);
  return s;
}

absl::StatusOr<SegmentEvalSummary> EvaluateSegment(
    const std::vector<LabelledFrame>& scenes,
    const SegmentEvalOptions& options) {
  if (options.folds < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("folds must be at least 2, got ", options.folds));
  }
  SegmentOptions segment = options.segment;
  segment.seeds.clear();
  if (absl::Status s = Validate(segment); !s.ok()) return s;
  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
  }

  // COS: training examples of every scene, once; each fold trains on the
  // others'.
  std::vector<std::vector<SvmSample>> samples(scenes.size());
  for (size_t i = 0; segment.method == SegmentMethod::kCos && i < scenes.size();
       ++i) {
    absl::StatusOr<std::vector<SvmSample>> s = CollectCosSamples(
        scenes[i], static_cast<int>(i), segment.detect, segment.cos);
    if (!s.ok()) {
      return InScene(scenes[i].name, s.status());
    }
    samples[i] = *std::move(s);
  }

  std::vector<SceneSegmentResult> results;
  std::vector<double> cv_accuracy;
  for (int fold = 0; fold < options.folds; ++fold) {
    std::vector<SvmSample> train;
    std::vector<const LabelledFrame*> train_frames;
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (static_cast<int>(i) % options.folds == fold) continue;
      train.insert(train.end(), samples[i].begin(), samples[i].end());
      train_frames.push_back(&scenes[i]);
    }
    std::optional<LinearSvm> cos;
    std::optional<EbsModel> ebs;
    SegmentModels models;
    if (segment.method == SegmentMethod::kCos) {
      absl::StatusOr<LinearSvm> trained =
          TrainLinearSvm(train, CosFeatureNames(), "cos", options.svm);
      if (!trained.ok()) return trained.status();
      cos = *std::move(trained);
      models.cos = &*cos;
    } else {
      absl::StatusOr<EbsModel> trained =
          EbsModel::Train(train_frames, EbsTrainOptions{});
      if (!trained.ok()) return trained.status();
      ebs = *std::move(trained);
      models.ebs = &*ebs;
    }
    for (size_t i = fold; i < scenes.size(); i += options.folds) {
      const LabelledFrame& scene = scenes[i];
      std::vector<SeededMask> masks;
      std::optional<double> first_seconds;
      SegmentSinks sinks;
      sinks.object = [&](SegmentedObject object) {
        if (!first_seconds) first_seconds = object.seconds_since_start;
        masks.push_back({{object.seed.u, object.seed.v}, object.mask});
        return absl::OkStatus();
      };
      absl::StatusOr<SegmentSummary> run =
          RunSegment(scene.frame, segment, models, sinks);
      if (!run.ok()) {
        return InScene(scene.name, run.status());
      }
      SceneSegmentResult r;
      r.name = scene.name;
      r.kind = SceneKind(scene.name);
      r.score = ScoreSegmentation(scene.labels, masks, kMinObjectPixels);
      cv::Mat segments(scene.labels.size(), CV_32SC1, cv::Scalar(-1));
      for (size_t m = 0; m < masks.size(); ++m) {
        segments.setTo(static_cast<int>(m), masks[m].mask & (segments < 0));
      }
      r.whole_scene_f = WholeSceneF(scene.labels, segments, kMinObjectPixels);
      r.first_mask_ms = first_seconds.value_or(0.0) * 1e3;
      r.all_masks_ms = run->total_seconds * 1e3;
      if (options.verbose) {
        std::fprintf(stderr,
                     "%-8s fold %d  F all %.3f best %.3f first %.3f  P %.3f "
                     "R %.3f  objects %d/%d  masks %d (false %d)  %.0f ms\n",
                     r.name.c_str(), fold, r.score.f_all, r.score.f_best,
                     r.score.f_first, r.score.precision_all, r.score.recall_all,
                     r.score.objects_with_mask, r.score.objects, r.score.masks,
                     r.score.false_masks, r.all_masks_ms);
      }
      if (!options.out_dir.empty())
        WriteMasksPng(options.out_dir, scene, masks);
      results.push_back(std::move(r));
    }
  }
  SegmentEvalSummary summary = SummarizeSegment(results, "");
  return summary;
}

}  // namespace fovea::eval
