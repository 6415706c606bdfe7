#include "tools/eval/inc_eval.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/base/status_macros.h"
#include "core/baseline/scene_segmenters.h"
#include "core/frame/organized_cloud.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/scene_runner.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

constexpr int kMinObjectPixels = 50;

// Pixels of each ground-truth object with depth, by object id.
std::map<int, std::vector<cv::Point>> ObjectPixels(const LabelledFrame& scene) {
  std::map<int, std::vector<cv::Point>> pixels;
  for (int v = 0; v < scene.labels.rows; ++v) {
    for (int u = 0; u < scene.labels.cols; ++u) {
      const int object = ObjectId(scene.labels.at<int>(v, u));
      if (object > 0 && !std::isnan(scene.frame.depth.at<float>(v, u))) {
        pixels[object].emplace_back(u, v);
      }
    }
  }
  for (auto it = pixels.begin(); it != pixels.end();) {
    it = static_cast<int>(it->second.size()) < kMinObjectPixels
             ? pixels.erase(it)
             : std::next(it);
  }
  return pixels;
}

struct WholeRun {
  std::vector<SeededMask> masks;
  cv::Mat segments;  // CV_32S, object index or -1
  double first_ms = 0.0;
  double total_ms = 0.0;
};

absl::StatusOr<WholeRun> RunToTheEnd(const LabelledFrame& scene,
                                     const IncrementalOptions& options,
                                     const RbfSvm& svm) {
  WholeRun run;
  run.segments = cv::Mat(scene.labels.size(), CV_32SC1, cv::Scalar(-1));
  std::optional<double> first;
  SegmentSinks sinks;
  sinks.object = [&](SegmentedObject object) {
    if (!first) first = object.seconds_since_start;
    run.segments.setTo(object.index, object.mask);
    run.masks.push_back({{object.seed.u, object.seed.v}, object.mask});
    return absl::OkStatus();
  };
  FOVEA_ASSIGN_OR_RETURN(
      SegmentSummary summary,
      RunSegmentIncremental(scene.frame, options, &svm, sinks));
  run.first_ms = first.value_or(summary.total_seconds) * 1e3;
  run.total_ms = summary.total_seconds * 1e3;
  return run;
}

// Section 3.3.3's protocol: per object, sequences of points, the first on
// the object, the others on other objects without replacement; the mask of
// the first object INC emits belongs to the sequence's first point.
absl::StatusOr<std::vector<SeededMask>> RandomPointMasks(
    const LabelledFrame& scene, const IncEvalOptions& options,
    const RbfSvm& svm, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::map<int, std::vector<cv::Point>> objects = ObjectPixels(scene);
  std::vector<SeededMask> masks;
  for (const auto& [object, pixels] : objects) {
    for (int s = 0; s < options.sequences_per_object; ++s) {
      auto pick = [&rng](const std::vector<cv::Point>& from) {
        return from[std::uniform_int_distribution<size_t>(
            0, from.size() - 1)(rng)];
      };
      IncrementalOptions run = options.incremental;
      run.attention_points = {pick(pixels)};
      std::vector<int> others;
      for (const auto& [other, unused] : objects) {
        if (other != object) others.push_back(other);
      }
      std::shuffle(others.begin(), others.end(), rng);
      for (size_t k = 0;
           k < others.size() && static_cast<int>(run.attention_points.size()) <
                                    options.points_per_sequence;
           ++k) {
        run.attention_points.push_back(pick(objects.at(others[k])));
      }
      run.max_objects = 1;
      std::optional<SeededMask> mask;
      SegmentSinks sinks;
      sinks.object = [&](SegmentedObject o) {
        mask = SeededMask{run.attention_points[0], o.mask};
        return absl::OkStatus();
      };
      FOVEA_ASSIGN_OR_RETURN(
          SegmentSummary summary,
          RunSegmentIncremental(scene.frame, run, &svm, sinks));
      if (mask) masks.push_back(*std::move(mask));
    }
  }
  return masks;
}

void WriteScenePng(const std::string& dir, const LabelledFrame& scene,
                   const WholeRun& run) {
  cv::Mat bgr;
  cv::cvtColor(scene.frame.color, bgr, cv::COLOR_RGB2BGR);
  cv::Mat overlay = bgr.clone();
  for (size_t i = 0; i < run.masks.size(); ++i) {
    overlay.setTo(MaskColor(i), run.masks[i].mask);
  }
  cv::addWeighted(overlay, 0.55, bgr, 0.45, 0.0, overlay);
  for (size_t i = 0; i < run.masks.size(); ++i) {
    cv::putText(overlay, std::to_string(i + 1), run.masks[i].seed,
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  }
  cv::imwrite((std::filesystem::path(dir) / (scene.name + "_inc.png")).string(),
              overlay);
}

}  // namespace

IncEvalSummary SummarizeInc(const std::vector<IncSceneResult>& scenes,
                            const std::string& kind) {
  IncEvalSummary s;
  int scored = 0, objects = 0, with_mask = 0, masks = 0, false_masks = 0;
  std::vector<double> first, whole;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const IncSceneResult& r : scenes) {
    if (!kind.empty() && r.kind != kind) continue;
    s.scenes.push_back(r);
    objects += r.score.objects;
    with_mask += r.score.objects_with_mask;
    masks += r.score.masks;
    false_masks += r.score.false_masks;
    s.whole_scene_f += r.whole_scene_f;
    first.push_back(r.first_object_ms);
    whole.push_back(r.whole_scene_ms);
    sx += r.whole_scene_ms;
    sy += r.first_object_ms;
    sxx += r.whole_scene_ms * r.whole_scene_ms;
    sxy += r.whole_scene_ms * r.first_object_ms;
    if (r.score.objects_with_mask == 0) continue;
    ++scored;
    s.f_all += r.score.f_all;
    s.f_best += r.score.f_best;
    s.f_first += r.score.f_first;
  }
  const double n = static_cast<double>(s.scenes.size());
  if (scored > 0) {
    s.f_all /= scored;
    s.f_best /= scored;
    s.f_first /= scored;
  }
  if (n > 0) s.whole_scene_f /= n;
  s.object_recall = objects > 0 ? static_cast<double>(with_mask) / objects : 0;
  s.false_masks = masks > 0 ? static_cast<double>(false_masks) / masks : 0;
  s.first_object_ms_median = Median(first);
  s.whole_scene_ms_median = Median(whole);
  const double denominator = n * sxx - sx * sx;
  s.first_object_slope =
      n > 1 && denominator > 0 ? (n * sxy - sx * sy) / denominator : 0.0;
  return s;
}

absl::Status WriteComplexity(const std::vector<IncSceneResult>& scenes,
                             const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::vector<IncSceneResult> sorted = scenes;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return a.whole_scene_ms < b.whole_scene_ms;
  });
  std::ofstream csv(std::filesystem::path(dir) / "complexity.csv");
  csv << "scene,kind,objects_emitted,first_object_ms,whole_scene_ms,"
         "whole_scene_f\n";
  for (const IncSceneResult& r : sorted) {
    csv << absl::StrFormat("%s,%s,%d,%.1f,%.1f,%.4f\n", r.name, r.kind,
                           r.objects_emitted, r.first_object_ms,
                           r.whole_scene_ms, r.whole_scene_f);
  }
  if (!csv) return absl::InternalError("cannot write complexity.csv");
  // The plot: x = scenes by complexity, y = ms; whole scene (blue) and
  // first object (red).
  constexpr int kWidth = 800, kHeight = 400, kMargin = 50;
  cv::Mat plot(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_ms = 1.0;
  for (const IncSceneResult& r : sorted) {
    max_ms = std::max(max_ms, r.whole_scene_ms);
  }
  auto at = [&](size_t i, double ms) {
    const double x =
        sorted.size() > 1 ? static_cast<double>(i) / (sorted.size() - 1) : 0.5;
    return cv::Point(
        kMargin + static_cast<int>(x * (kWidth - 2 * kMargin)),
        kHeight - kMargin -
            static_cast<int>(ms / max_ms * (kHeight - 2 * kMargin)));
  };
  cv::line(plot, {kMargin, kHeight - kMargin},
           {kWidth - kMargin, kHeight - kMargin}, cv::Scalar(0, 0, 0));
  cv::line(plot, {kMargin, kMargin}, {kMargin, kHeight - kMargin},
           cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < sorted.size(); ++i) {
    cv::circle(plot, at(i, sorted[i].whole_scene_ms), 3, cv::Scalar(200, 80, 0),
               cv::FILLED);
    cv::circle(plot, at(i, sorted[i].first_object_ms), 3, cv::Scalar(0, 0, 220),
               cv::FILLED);
    if (i > 0) {
      cv::line(plot, at(i - 1, sorted[i - 1].whole_scene_ms),
               at(i, sorted[i].whole_scene_ms), cv::Scalar(200, 80, 0));
      cv::line(plot, at(i - 1, sorted[i - 1].first_object_ms),
               at(i, sorted[i].first_object_ms), cv::Scalar(0, 0, 220));
    }
  }
  cv::putText(plot, absl::StrFormat("ms (max %.0f)", max_ms), {5, 30},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0));
  cv::putText(plot, "scenes, ordered by whole-scene time (complexity)",
              {kMargin, kHeight - 15}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(0, 0, 0));
  cv::putText(plot, "whole scene", {kWidth - 200, 30}, cv::FONT_HERSHEY_SIMPLEX,
              0.5, cv::Scalar(200, 80, 0));
  cv::putText(plot, "first object", {kWidth - 200, 50},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 220));
  if (!cv::imwrite((std::filesystem::path(dir) / "complexity.png").string(),
                   plot)) {
    return absl::InternalError("cannot write complexity.png");
  }
  return absl::OkStatus();
}

absl::StatusOr<IncEvalSummary> EvaluateInc(
    const std::vector<LabelledFrame>& scenes, const IncEvalOptions& options) {
  if (options.folds < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("folds must be at least 2, got ", options.folds));
  }
  IncrementalOptions run = options.incremental;
  run.attention_points.clear();
  FOVEA_RETURN_IF_ERROR(Validate(run));
  std::vector<std::vector<SvmSample>> samples(scenes.size());
  for (size_t i = 0; i < scenes.size(); ++i) {
    absl::StatusOr<std::vector<SvmSample>> s =
        CollectIncSamples(scenes[i], static_cast<int>(i), run.detect, run.inc);
    if (!s.ok()) {
      return InScene(scenes[i].name, s.status());
    }
    samples[i] = *std::move(s);
  }
  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
  }
  std::vector<IncSceneResult> results;
  for (int fold = 0; fold < options.folds; ++fold) {
    std::vector<SvmSample> train;
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (static_cast<int>(i) % options.folds == fold) continue;
      train.insert(train.end(), samples[i].begin(), samples[i].end());
    }
    FOVEA_ASSIGN_OR_RETURN(
        RbfSvm svm,
        TrainRbfSvm(train, RelationFeatureNames(), "inc", options.svm));
    for (size_t i = fold; i < scenes.size(); i += options.folds) {
      const LabelledFrame& scene = scenes[i];
      absl::StatusOr<WholeRun> whole = RunToTheEnd(scene, run, svm);
      if (!whole.ok()) {
        return InScene(scene.name, whole.status());
      }
      IncSceneResult r;
      r.name = scene.name;
      r.kind = SceneKind(scene.name);
      r.whole_scene_f =
          WholeSceneF(scene.labels, whole->segments, kMinObjectPixels);
      r.first_object_ms = whole->first_ms;
      r.whole_scene_ms = whole->total_ms;
      r.objects_emitted = static_cast<int>(whole->masks.size());
      if (options.saliency == IncSaliency::kSym3d) {
        r.score =
            ScoreSegmentation(scene.labels, whole->masks, kMinObjectPixels);
      } else {
        FOVEA_ASSIGN_OR_RETURN(std::vector<SeededMask> masks,
                               RandomPointMasks(scene, options, svm, 1000 + i));
        r.score = ScoreSegmentation(scene.labels, masks, kMinObjectPixels);
      }
      if (options.verbose) {
        std::fprintf(stderr,
                     "%-8s fold %d  whole F %.3f  F all %.3f best %.3f first "
                     "%.3f  objects %d/%d  emitted %d  first %.0f ms  whole "
                     "%.0f ms\n",
                     r.name.c_str(), fold, r.whole_scene_f, r.score.f_all,
                     r.score.f_best, r.score.f_first, r.score.objects_with_mask,
                     r.score.objects, r.objects_emitted, r.first_object_ms,
                     r.whole_scene_ms);
      }
      if (!options.out_dir.empty()) {
        WriteScenePng(options.out_dir, scene, *whole);
      }
      results.push_back(std::move(r));
    }
  }
  if (!options.out_dir.empty()) {
    FOVEA_RETURN_IF_ERROR(WriteComplexity(results, options.out_dir));
  }
  return SummarizeInc(results, "");
}

}  // namespace fovea::eval
