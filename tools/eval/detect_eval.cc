#include "tools/eval/detect_eval.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/attention/tj.h"
#include "core/base/status_macros.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/osd_pcd.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

std::string ResolveDataDir(const std::string& dir) {
  const std::filesystem::path learn = std::filesystem::path(dir) / "learn";
  if (std::filesystem::is_directory(learn)) return learn.string();
  return dir;
}

// Drawing of the attention points on the evaluation PNGs.
constexpr int kPointRadiusPx = 6;
const cv::Point kLabelOffset(7, -7);
constexpr double kLabelScale = 0.5;

// Saliency map in false colour with the points numbered on it, next to the
// colour image with the ground-truth object outlines.
void WriteScenePng(const std::string& out_dir, const LabelledFrame& scene,
                   const DetectResult& result, const DetectOptions& options) {
  cv::Mat map8;
  result.master.convertTo(map8, CV_8UC1, 255.0);
  cv::Mat heat;
  cv::applyColorMap(map8, heat, cv::COLORMAP_JET);
  if (options.extraction == ExtractionKind::kTj) {
    // The skeletons TJ found its points on, drawn in white (the support is
    // TJ's: pixels above support_fraction of the maximum).
    double max_value = 0.0;
    cv::minMaxLoc(result.master, nullptr, &max_value);
    const cv::Mat support =
        result.master > std::max(options.tj.support_fraction * max_value, 0.0);
    absl::StatusOr<cv::Mat> skeleton = ThinToSkeleton(support);
    if (skeleton.ok()) {
      cv::Mat visible;  // 3 px wide, so it shows at full size
      cv::dilate(*skeleton, visible, cv::Mat());
      heat.setTo(cv::Scalar(255, 255, 255), visible);
    }
  }
  cv::Mat bgr;
  cv::cvtColor(scene.frame.color, bgr, cv::COLOR_RGB2BGR);
  // One outline per ground-truth object (all of its labelled parts).
  cv::Mat ids(scene.labels.size(), CV_32SC1);
  int max_id = 0;
  for (int v = 0; v < ids.rows; ++v) {
    for (int u = 0; u < ids.cols; ++u) {
      const int id = ObjectId(scene.labels.at<int>(v, u));
      ids.at<int>(v, u) = id;
      max_id = std::max(max_id, id);
    }
  }
  std::vector<std::vector<cv::Point>> contours;
  for (int id = 1; id <= max_id; ++id) {
    const cv::Mat mask = ids == id;
    if (cv::countNonZero(mask) == 0) continue;
    std::vector<std::vector<cv::Point>> c;
    cv::findContours(mask, c, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    contours.insert(contours.end(), c.begin(), c.end());
  }
  cv::drawContours(bgr, contours, -1, cv::Scalar(255, 255, 255), 1);
  const cv::Scalar white(255, 255, 255);
  for (size_t i = 0; i < result.points.size(); ++i) {
    const cv::Point p(result.points[i].u, result.points[i].v);
    for (cv::Mat* img : {&heat, &bgr}) {
      cv::circle(*img, p, kPointRadiusPx, white, 2);
      cv::putText(*img, std::to_string(i), p + kLabelOffset,
                  cv::FONT_HERSHEY_SIMPLEX, kLabelScale, white, 1);
    }
  }
  cv::Mat both;
  cv::hconcat(bgr, heat, both);
  cv::imwrite(out_dir + "/" + scene.name + ".png", both);
}

// The pcl-clusters peer in DetectResult form (no saliency map: the master
// map is the candidate mask, for the PNGs).
absl::StatusOr<DetectResult> RunPclClusters(const RgbdFrame& frame,
                                            const DetectEvalOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud,
                         BuildOrganizedCloud(frame, options.detect.normals));
  FOVEA_ASSIGN_OR_RETURN(SupportPlane plane,
                         FindSupportPlane(cloud, options.detect.support_plane));
  const TableScene scene =
      PrepareTableScene(cloud, plane, options.detect.table_scene);
  FOVEA_ASSIGN_OR_RETURN(
      std::vector<AttentionPoint> points,
      DetectPclClusters(cloud, scene, options.detect.max_points,
                        options.clusters));
  DetectResult result;
  result.points = std::move(points);
  scene.candidate.convertTo(result.master, CV_32FC1, 1.0 / 255.0);
  result.plane = std::move(plane);
  return result;
}

}  // namespace

DetectEvalSummary Summarize(const std::vector<SceneResult>& scenes,
                            const std::string& kind) {
  DetectEvalSummary s;
  std::vector<double> times;
  for (const SceneResult& r : scenes) {
    if (!kind.empty() && r.kind != kind) continue;
    s.scenes.push_back(r);
    s.hit_ratio += r.score.hit_ratio;
    s.hit_ratio_all_points += r.hit_ratio_all_points;
    s.repeated_points += r.score.repeated_points;
    s.off_object_points += r.score.off_object_points;
    s.distance_to_center += r.score.distance_to_center;
    s.distance_to_center_thesis += r.score.distance_to_center_thesis;
    for (int i = 0; i < kHitRatioAtMax; ++i) {
      s.hit_ratio_at[i] += r.score.hit_ratio_at[i];
    }
    times.push_back(r.detect_ms);
  }
  const double n = static_cast<double>(s.scenes.size());
  if (n > 0) {
    s.hit_ratio /= n;
    s.hit_ratio_all_points /= n;
    s.repeated_points /= n;
    s.off_object_points /= n;
    s.distance_to_center /= n;
    s.distance_to_center_thesis /= n;
    for (double& h : s.hit_ratio_at) h /= n;
  }
  s.detect_ms_median = Median(times);
  return s;
}

absl::StatusOr<std::vector<LabelledFrame>> LoadScenes(
    const std::string& data_dir) {
  FOVEA_ASSIGN_OR_RETURN(std::vector<std::string> files,
                         ListPcdFiles(ResolveDataDir(data_dir)));
  if (files.empty()) {
    return absl::NotFoundError("no .pcd files in " + data_dir);
  }
  std::vector<LabelledFrame> scenes;
  scenes.reserve(files.size());
  for (const std::string& path : files) {
    FOVEA_ASSIGN_OR_RETURN(LabelledFrame scene, LoadOsdPcd(path));
    scenes.push_back(std::move(scene));
  }
  return scenes;
}

absl::StatusOr<DetectEvalSummary> EvaluateDetectOn(
    const std::vector<LabelledFrame>& scenes,
    const DetectEvalOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options.detect));
  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
  }
  std::vector<SceneResult> results;
  for (const LabelledFrame& scene : scenes) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<DetectResult> result =
        options.pcl_clusters ? RunPclClusters(scene.frame, options)
                             : RunDetect(scene.frame, options.detect);
    const double ms = std::chrono::duration<double, std::milli>(
                          std::chrono::steady_clock::now() - start)
                          .count();
    if (!result.ok()) {
      return absl::Status(
          result.status().code(),
          scene.name + ": " + std::string(result.status().message()));
    }
    const OrganizedCloud cloud = BackProject(scene.frame);
    SceneResult r;
    r.name = scene.name;
    r.kind = SceneKind(scene.name);
    // The thesis's HR: the first max(K, 10) points, however many Detect
    // returned; and, beside it, HR over every point returned.
    r.score = ScoreAttentionPoints(result->points, scene.labels, cloud.xyz,
                                   kHitRatioAtMax);
    r.hit_ratio_all_points =
        ScoreAttentionPoints(result->points, scene.labels, cloud.xyz,
                             static_cast<int>(result->points.size()))
            .hit_ratio;
    r.points = static_cast<int>(result->points.size());
    r.detect_ms = ms;
    if (options.verbose) {
      std::fprintf(stderr,
                   "%-10s %-10s objects %2d hits %2d HR %.2f DC %.2f "
                   "DC(thesis) %.2f %6.1f ms\n",
                   r.name.c_str(), r.kind.c_str(), r.score.objects,
                   r.score.hits, r.score.hit_ratio, r.score.distance_to_center,
                   r.score.distance_to_center_thesis, ms);
    }
    if (!options.out_dir.empty())
      WriteScenePng(options.out_dir, scene, *result, options.detect);
    if (r.score.objects > 0) results.push_back(std::move(r));
  }
  return Summarize(results, "");
}

absl::StatusOr<DetectEvalSummary> EvaluateDetect(
    const DetectEvalOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options.detect));
  FOVEA_ASSIGN_OR_RETURN(std::vector<LabelledFrame> scenes,
                         LoadScenes(options.data_dir));
  return EvaluateDetectOn(scenes, options);
}

}  // namespace fovea::eval
