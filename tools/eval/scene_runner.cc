#include "tools/eval/scene_runner.h"

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/baseline/scene_segmenters.h"
#include "core/frame/organized_cloud.h"
#include "core/pipeline/incremental.h"

namespace fovea::eval {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start)
      .count();
}

// The mask's pixel nearest its centroid.
cv::Point CentralPixel(const cv::Mat& mask) {
  const cv::Moments m = cv::moments(mask, true);
  const cv::Point2d c(m.m10 / std::max(m.m00, 1.0),
                      m.m01 / std::max(m.m00, 1.0));
  std::vector<cv::Point> pixels;
  cv::findNonZero(mask, pixels);
  cv::Point best = pixels.empty() ? cv::Point() : pixels[0];
  double best_d = 1e30;
  for (const cv::Point& p : pixels) {
    const double d = (p.x - c.x) * (p.x - c.x) + (p.y - c.y) * (p.y - c.y);
    if (d < best_d) {
      best_d = d;
      best = p;
    }
  }
  return best;
}

absl::StatusOr<SceneRun> RunPeer(const LabelledFrame& scene,
                                 SceneMethod method) {
  SceneRun run;
  const Clock::time_point start = Clock::now();
  FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud,
                         BuildOrganizedCloud(scene.frame, NormalOptions{}));
  FOVEA_ASSIGN_OR_RETURN(
      SceneSegmentation segmentation,
      method == SceneMethod::kPclEuclidean
          ? SegmentSceneEuclidean(cloud, EuclideanSceneOptions{})
          : SegmentSceneLccp(cloud, LccpSceneOptions{}));
  run.total_ms = run.first_ms = MsSince(start);
  run.segments = cv::Mat(scene.labels.size(), CV_32SC1, cv::Scalar(-1));
  for (int s = 0; s < segmentation.segments; ++s) {
    cv::Mat mask = segmentation.labels == s;
    if (cv::countNonZero(mask) == 0) continue;
    run.segments.setTo(static_cast<int>(run.masks.size()), mask);
    run.masks.push_back({CentralPixel(mask), mask});
  }
  return run;
}

}  // namespace

absl::Span<const NamedValue<SceneMethod>> SceneMethods() {
  static constexpr NamedValue<SceneMethod> kTable[] = {
      {SceneMethod::kInc, "inc"},
      {SceneMethod::kCos, "cos"},
      {SceneMethod::kEbs, "ebs"},
      {SceneMethod::kPclLccp, "pcl-lccp"},
      {SceneMethod::kPclEuclidean, "pcl-euclidean"},
  };
  return kTable;
}

std::string_view SceneMethodName(SceneMethod method) {
  return NameOf(SceneMethods(), method);
}

absl::StatusOr<SceneMethod> ParseSceneMethod(std::string_view text) {
  return ParseNamed(SceneMethods(), "", "method", text);
}

absl::StatusOr<SceneRun> RunOnScene(const LabelledFrame& scene,
                                    const SceneRunOptions& options) {
  if (options.method == SceneMethod::kPclLccp ||
      options.method == SceneMethod::kPclEuclidean) {
    return RunPeer(scene, options.method);
  }
  SceneRun run;
  run.segments = cv::Mat(scene.labels.size(), CV_32SC1, cv::Scalar(-1));
  const Clock::time_point start = Clock::now();
  bool first = true;
  SegmentSinks sinks;
  sinks.support = [&](const SupportPlane& plane) {
    run.support = plane;
    return absl::OkStatus();
  };
  sinks.points = [&](const std::vector<AttentionPoint>& points) {
    run.points = points;
    return absl::OkStatus();
  };
  sinks.object = [&](SegmentedObject object) {
    if (first) run.first_ms = MsSince(start);
    first = false;
    // Earlier objects keep their pixels.
    run.segments.setTo(static_cast<int>(run.masks.size()),
                       object.mask & (run.segments < 0));
    run.masks.push_back(
        {{object.seed.u, object.seed.v}, std::move(object.mask)});
    return absl::OkStatus();
  };
  absl::StatusOr<SegmentSummary> summary;
  if (options.method == SceneMethod::kInc) {
    IncrementalOptions inc;
    inc.detect = options.detect;
    summary = RunSegmentIncremental(
        scene.frame, inc, options.models.IncFor(scene.frame, inc.detect.scene),
        sinks);
  } else {
    SegmentOptions segment;
    FOVEA_ASSIGN_OR_RETURN(segment.method,
                           ParseSegmentMethod(SceneMethodName(options.method)));
    segment.detect = options.detect;
    segment.cover_scene = options.cover_scene;
    summary = RunSegment(scene.frame, segment, options.models, sinks);
  }
  if (!summary.ok()) return summary.status();
  run.total_ms = MsSince(start);
  if (first) run.first_ms = run.total_ms;
  return run;
}

}  // namespace fovea::eval
