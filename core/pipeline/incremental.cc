#include "core/pipeline/incremental.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/base/stage_clock.h"
#include "core/base/status_macros.h"
#include "core/pipeline/sensor_adaptation.h"

namespace fovea {
namespace {

// Focal length the attention sigma is given at, pixels.
constexpr double kReferenceFocalPx = 525.0;

}  // namespace

absl::Status Validate(const IncrementalOptions& options) {
  if (absl::Status s = Validate(options.detect); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("detect: ", s.message()));
  }
  if (absl::Status s = Validate(options.inc); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("inc.", s.message()));
  }
  if (options.attention_points.size() >
      static_cast<size_t>(kMaxAttentionPoints)) {
    return absl::InvalidArgumentError(
        absl::StrCat("attention_points: ", options.attention_points.size(),
                     " given, at most ", kMaxAttentionPoints, " allowed"));
  }
  if (!(options.attention_sigma_px > 0.0f)) {
    return absl::InvalidArgumentError("attention_sigma_px must be positive");
  }
  if (options.max_objects < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_objects must not be negative, got ", options.max_objects));
  }
  if (!(options.min_object_area_m2 >= 0.0) ||
      !std::isfinite(options.min_object_area_m2)) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_object_area_m2 must be finite and >= 0, got ",
                     options.min_object_area_m2));
  }
  if (!(options.time_budget_seconds >= 0.0) ||
      !std::isfinite(options.time_budget_seconds)) {
    return absl::InvalidArgumentError(
        absl::StrCat("time_budget_seconds must be a non-negative number, got ",
                     options.time_budget_seconds));
  }
  if (!(options.change_weight >= 0.0f && options.change_weight <= 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "change_weight must be in [0, 1], got ", options.change_weight));
  }
  if (!options.change.empty() && options.change.type() != CV_8UC1) {
    return absl::InvalidArgumentError("change must be CV_8UC1");
  }
  FOVEA_RETURN_IF_ERROR(Validate(options.box_fit));
  return Validate(options.object_points);
}

cv::Mat WithChangeCue(const cv::Mat& saliency, const cv::Mat& change,
                      float weight) {
  // Blurred at a quarter of the map's size (a 6 px Gaussian over 640 x 480
  // floats cost about 4 ms a frame), then brought up to it.
  const cv::Size small(std::max(1, saliency.cols / 4),
                       std::max(1, saliency.rows / 4));
  cv::Mat cue;
  cv::resize(change, cue, small, 0.0, 0.0, cv::INTER_AREA);
  cue.convertTo(cue, CV_32FC1, 1.0 / 255.0);
  cv::GaussianBlur(cue, cue, cv::Size(),
                   std::max(0.5, 0.01 * saliency.cols / 4.0));
  cv::resize(cue, cue, saliency.size(), 0.0, 0.0, cv::INTER_LINEAR);
  double cue_max = 0.0;
  cv::minMaxLoc(cue, nullptr, &cue_max);
  if (cue_max <= 0.0) return saliency;  // nothing changed
  double saliency_max = 0.0;
  cv::minMaxLoc(saliency, nullptr, &saliency_max);
  cv::Mat out;
  cv::addWeighted(saliency,
                  saliency_max > 0.0 ? (1.0 - weight) / saliency_max : 0.0, cue,
                  weight / cue_max, 0.0, out);
  return out;
}

cv::Mat AttentionPointsSaliency(const std::vector<cv::Point>& points,
                                cv::Size size, float sigma_px) {
  cv::Mat map(size, CV_32FC1, cv::Scalar(0));
  const double n = static_cast<double>(points.size());
  const double two_s2 = 2.0 * sigma_px * sigma_px;
  for (size_t i = 0; i < points.size(); ++i) {
    const double weight = (n - static_cast<double>(i)) / n;
    for (int v = 0; v < size.height; ++v) {
      float* row = map.ptr<float>(v);
      const double dv = v - points[i].y;
      for (int u = 0; u < size.width; ++u) {
        const double du = u - points[i].x;
        row[u] += static_cast<float>(weight *
                                     std::exp(-(du * du + dv * dv) / two_s2));
      }
    }
  }
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  if (max_value > 0.0) map /= max_value;
  return map;
}

absl::StatusOr<SegmentSummary> RunSegmentIncremental(
    const RgbdFrame& frame, const IncrementalOptions& options,
    const RbfSvm* svm, const SegmentSinks& sinks,
    const InterruptCheck& interrupt, SteadyClock::time_point start) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  for (const cv::Point& p : options.attention_points) {
    if (p.x < 0 || p.y < 0 || p.x >= frame.width() || p.y >= frame.height()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "attention_points: (", p.x, ", ", p.y, ") lies outside the ",
          frame.width(), "x", frame.height(), " frame"));
    }
  }
  if (!options.change.empty() && options.change.size() != frame.depth.size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "change: ", options.change.cols, "x", options.change.rows,
        " is not the frame's ", frame.width(), "x", frame.height()));
  }
  if (svm == nullptr) {
    return absl::FailedPreconditionError(
        "segment-incremental: no relation SVM is loaded");
  }
  SegmentSummary summary;
  FOVEA_ASSIGN_OR_RETURN(PreparedScene scene,
                         PrepareScene(frame, options.detect, interrupt));
  summary.timings = scene.timings;
  if (sinks.support) {
    FOVEA_RETURN_IF_ERROR(
        sinks.support(PlaneToInput(scene.scale, scene.plane)));
  }

  std::vector<AttentionPoint> points;
  cv::Mat saliency;
  // The surface models' noise is the scene's sensor's.
  IncOptions inc_options = options.inc;
  AdaptToSensor(scene.sensor, inc_options.surface_models);
  AdaptToSensor(scene.sensor, inc_options.body_join.fit);
  // The surfaces do not depend on the saliency map: with two threads they
  // are built while Detect runs.
  std::optional<absl::StatusOr<CosScene>> surfaces;
  double surfaces_seconds = 0.0;
  const auto build_surfaces = [&] {
    const SteadyClock::time_point at = SteadyClock::now();
    surfaces = BuildCosScene(scene.cloud, scene.plane, inc_options.surfaces,
                             scene.table.region);
    surfaces_seconds = SecondsSince(at);
  };
  if (!options.attention_points.empty()) {
    const float sigma =
        static_cast<float>(options.attention_sigma_px *
                           scene.cloud.intrinsics.fx / kReferenceFocalPx);
    std::vector<cv::Point> attention;
    for (const cv::Point& p : options.attention_points) {
      attention.push_back(scene.scale.ToProcessing(p));
    }
    saliency =
        AttentionPointsSaliency(attention, scene.cloud.xyz.size(), sigma);
    for (const cv::Point& p : attention) {
      AttentionPoint a;
      a.u = p.x;
      a.v = p.y;
      a.saliency = saliency.at<float>(p);
      const cv::Vec3f& q = scene.cloud.xyz.at<cv::Vec3f>(p);
      a.point = {q[0], q[1], q[2]};
      points.push_back(a);
    }
  } else {
    absl::StatusOr<DetectResult> detect;
    ParallelInvoke(
        [&] { detect = DetectOnScene(scene, options.detect, interrupt); },
        build_surfaces);
    FOVEA_RETURN_IF_ERROR(detect.status());
    summary.timings.insert(summary.timings.end(), detect->timings.begin(),
                           detect->timings.end());
    saliency = std::move(detect->master);
    points = std::move(detect->points);
  }
  if (sinks.points) {
    FOVEA_RETURN_IF_ERROR(sinks.points(PointsToInput(scene.scale, points)));
  }
  FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));

  if (!options.change.empty()) {
    saliency = WithChangeCue(saliency, options.change, options.change_weight);
  }
  if (!surfaces.has_value()) build_surfaces();
  FOVEA_RETURN_IF_ERROR(surfaces->status());
  SteadyClock::time_point lap = SteadyClock::now();
  FOVEA_ASSIGN_OR_RETURN(IncScene inc,
                         BuildIncScene(**std::move(surfaces), scene.cloud,
                                       scene.plane, saliency, inc_options));
  IncSegmenter segmenter(inc, *svm, inc_options);
  // With two threads, the surfaces' part overlapped Detect's stages.
  summary.timings.push_back(
      {"segment.prepare", surfaces_seconds + SecondsSince(lap)});
  for (const StageTiming& part : inc.timings) {
    summary.timings.push_back({absl::StrCat("inc.", part.stage), part.seconds});
  }

  while (true) {
    if (options.max_objects > 0 && summary.objects >= options.max_objects) {
      summary.stop = SegmentStop::kMaxObjects;
      break;
    }
    if (options.time_budget_seconds > 0.0 &&
        SecondsSince(start) >= options.time_budget_seconds) {
      summary.stop = SegmentStop::kTimeBudget;
      break;
    }
    FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
    lap = SteadyClock::now();
    FOVEA_ASSIGN_OR_RETURN(std::optional<IncObject> next,
                           segmenter.Next(interrupt));
    summary.timings.push_back({"segment.object", SecondsSince(lap)});
    if (!next.has_value()) break;  // the scene is exhausted
    if (VisibleArea(scene.cloud, next->mask, next->box) <
            options.min_object_area_m2 ||
        StandingShare(scene.table, next->mask, next->box) < kMinStandingShare) {
      continue;  // a fragment, or not on the table: it left the scene, but
                 // is not reported
    }
    SegmentedObject object;
    object.seed.u = next->seed.x;
    object.seed.v = next->seed.y;
    object.seed.saliency = static_cast<float>(next->saliency);
    const cv::Vec3f& q = scene.cloud.xyz.at<cv::Vec3f>(next->seed);
    object.seed.point = {q[0], q[1], q[2]};
    object.mask = std::move(next->mask);
    object.score = next->score;
    DescribeObject(scene.cloud, object, next->box);
    DescribeGeometry(scene.cloud, scene.plane, options.box_fit,
                     options.object_points, object, next->box);
    ObjectToInput(scene.scale, object);
    ObjectIndicesToInput(options.object_points, object);
    object.index = summary.objects++;
    object.seconds_since_start = SecondsSince(start);
    if (sinks.object) {
      FOVEA_RETURN_IF_ERROR(sinks.object(std::move(object)));
    }
  }
  summary.scene_coverage = segmenter.coverage();
  summary.total_seconds = SecondsSince(start);
  return summary;
}

absl::StatusOr<std::vector<SvmSample>> CollectIncSamples(
    const LabelledFrame& frame, int group, const DetectOptions& detect,
    const IncOptions& inc) {
  FOVEA_ASSIGN_OR_RETURN(PreparedScene scene,
                         PrepareScene(frame.frame, MeasuredDepthOnly(detect)));
  const cv::Mat flat(frame.frame.depth.size(), CV_32FC1, cv::Scalar(0));
  FOVEA_ASSIGN_OR_RETURN(
      IncScene inc_scene,
      BuildIncScene(scene.cloud, scene.plane, flat, inc, scene.table.region));
  return IncTrainingSamples(inc_scene, frame.labels, group);
}

}  // namespace fovea
