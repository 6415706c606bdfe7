#include "tools/eval/room_eval.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/eval/hungarian.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

constexpr double kMaxSupportAngleDeg = 5.0;
constexpr double kMaxSupportOffset = 0.02;  // metres
constexpr double kMinSupportShare = 0.5;
constexpr int kMinObjectPixels640 = 50;  // at 640 x 480
constexpr double kFoundF = 0.5;
constexpr double kOverlayAlpha = 0.55;

// Ground-truth object ids (0 none) of the frame.
bool SupportCorrect(const synth::SynthScene& truth,
                    const std::optional<SupportPlane>& plane) {
  if (!plane.has_value() || plane->inliers.empty()) return false;
  if (plane->normal.dot(truth.table_normal_camera) <
      std::cos(kMaxSupportAngleDeg * M_PI / 180.0)) {
    return false;
  }
  if (std::abs(plane->d - truth.table_d_camera) > kMaxSupportOffset)
    return false;
  const cv::Mat on_table = truth.frame.labels == synth::kSupportTableLabel;
  const int inliers = cv::countNonZero(plane->inliers);
  return inliers > 0 && cv::countNonZero(plane->inliers & on_table) >=
                            kMinSupportShare * inliers;
}

// Whether most of the mask's labelled pixels are not an object.
bool OnSomethingElse(const cv::Mat& mask, const cv::Mat& labels) {
  int object = 0, other = 0;
  for (int v = 0; v < mask.rows; ++v) {
    const uint8_t* m = mask.ptr<uint8_t>(v);
    const int* l = labels.ptr<int>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (!m[u] || l[u] == 0) continue;
      (ObjectId(l[u]) > 0 ? object : other) += 1;
    }
  }
  return other > object;
}

void WritePng(const std::string& dir, const synth::SynthScene& truth,
              const SceneRun& run) {
  cv::Mat bgr;
  cv::cvtColor(truth.frame.frame.color, bgr, cv::COLOR_RGB2BGR);
  cv::Mat overlay = bgr.clone();
  if (run.support.has_value()) {
    overlay.setTo(cv::Scalar(0, 200, 0), run.support->inliers);
  }
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
  ObjectIdImage(truth.frame.labels).convertTo(objects, CV_8U, 20);
  cv::Mat edges;
  cv::Canny(objects, edges, 1, 1);
  cv::Mat gt = bgr.clone();
  gt.setTo(cv::Scalar(0, 255, 255),
           truth.frame.labels == synth::kSupportTableLabel);
  cv::addWeighted(gt, 0.3, bgr, 0.7, 0.0, gt);
  gt.setTo(cv::Scalar(0, 0, 255), edges);
  cv::Mat both;
  cv::hconcat(overlay, gt, both);
  cv::imwrite(
      (std::filesystem::path(dir) / (truth.frame.name + ".png")).string(),
      both);
}

RoomResult Score(const synth::SynthScene& truth, const SceneRun& run,
                 const std::string& group) {
  RoomResult r;
  r.name = truth.frame.name;
  r.group = group;
  r.first_ms = run.first_ms;
  r.total_ms = run.total_ms;
  r.support_correct = SupportCorrect(truth, run.support);
  const cv::Mat& labels = truth.frame.labels;
  const int min_pixels =
      std::max(1, static_cast<int>(std::lround(
                      kMinObjectPixels640 * labels.total() / (640.0 * 480.0))));
  const cv::Mat ids = ObjectIdImage(labels);
  r.uois = ScoreUois(ids, run.segments, min_pixels);
  r.whole_scene_f = WholeSceneF(labels, run.segments, min_pixels);
  r.masks = static_cast<int>(run.masks.size());
  for (const SeededMask& m : run.masks)
    r.false_objects += OnSomethingElse(m.mask, labels);
  // Objects found: matched one to one with F >= 0.5.
  std::map<int, int> pixels;
  for (int v = 0; v < ids.rows; ++v) {
    const int* row = ids.ptr<int>(v);
    for (int u = 0; u < ids.cols; ++u) {
      if (row[u] > 0) ++pixels[row[u]];
    }
  }
  std::vector<int> objects;
  for (const auto& [id, n] : pixels) {
    if (n >= min_pixels) objects.push_back(id);
  }
  r.objects = static_cast<int>(objects.size());
  std::vector<std::vector<double>> f(
      objects.size(), std::vector<double>(run.masks.size(), 0.0));
  for (size_t j = 0; j < run.masks.size(); ++j) {
    const int area = cv::countNonZero(run.masks[j].mask);
    for (size_t i = 0; i < objects.size(); ++i) {
      const int both =
          cv::countNonZero(run.masks[j].mask & (ids == objects[i]));
      f[i][j] = area + pixels[objects[i]] > 0
                    ? 2.0 * both / (area + pixels[objects[i]])
                    : 0.0;
    }
  }
  const std::vector<int> match = MaxWeightAssignment(f);
  for (size_t i = 0; i < objects.size(); ++i) {
    r.objects_found += match[i] >= 0 && f[i][match[i]] >= kFoundF;
  }
  return r;
}

}  // namespace

absl::StatusOr<std::vector<RoomResult>> EvaluateRooms(
    const RoomEvalOptions& options) {
  if (options.count < 1) {
    return absl::InvalidArgumentError("rooms: --count must be >= 1");
  }
  if (!options.out_dir.empty())
    std::filesystem::create_directories(options.out_dir);
  std::vector<RoomResult> results;
  for (const synth::RoomSensor sensor : options.sensors) {
    for (const cv::Size& size : options.sizes) {
      synth::RoomOptions room = options.room;
      room.sensor = sensor;
      room.width = size.width;
      room.height = size.height;
      FOVEA_RETURN_IF_ERROR(synth::Validate(room));
      const std::string group =
          absl::StrCat(AbslView(synth::RoomSensorName(sensor)), " ", size.width,
                       "x", size.height);
      for (int k = 0; k < options.count; ++k) {
        const synth::SynthScene truth =
            synth::GenerateRoom(options.seed + k, room);
        absl::StatusOr<SceneRun> run = RunOnScene(truth.frame, options.run);
        if (!run.ok() && run.status().code() != absl::StatusCode::kNotFound) {
          return InScene(truth.frame.name, run.status());
        }
        SceneRun none;
        none.segments =
            cv::Mat(truth.frame.labels.size(), CV_32SC1, cv::Scalar(-1));
        const SceneRun& used = run.ok() ? *run : none;
        RoomResult r = Score(truth, used, group);
        if (options.verbose) {
          std::fprintf(stderr,
                       "%-32s support %s  objects %d/%d  false %d  overlap F "
                       "%.3f  %.0f ms\n",
                       r.name.c_str(), r.support_correct ? "ok " : "BAD",
                       r.objects_found, r.objects, r.false_objects,
                       r.uois.overlap_f, r.total_ms);
        }
        if (!options.out_dir.empty()) WritePng(options.out_dir, truth, used);
        results.push_back(std::move(r));
      }
    }
  }
  return results;
}

RoomSummary SummarizeRooms(const std::vector<RoomResult>& results,
                           const std::string& group) {
  RoomSummary s;
  s.group = group;
  int objects = 0, found = 0, false_objects = 0;
  std::vector<double> first, total;
  for (const RoomResult& r : results) {
    if (!group.empty() && r.group != group) continue;
    ++s.rooms;
    s.support_correct += r.support_correct;
    objects += r.objects;
    found += r.objects_found;
    false_objects += r.false_objects;
    s.overlap_p += r.uois.overlap_p;
    s.overlap_r += r.uois.overlap_r;
    s.overlap_f += r.uois.overlap_f;
    s.boundary_f += r.uois.boundary_f;
    s.objects_075 += r.uois.objects_075;
    s.whole_scene_f += r.whole_scene_f;
    first.push_back(r.first_ms);
    total.push_back(r.total_ms);
  }
  if (s.rooms == 0) return s;
  const double n = s.rooms;
  s.support_correct /= n;
  s.object_recall = objects > 0 ? static_cast<double>(found) / objects : 0.0;
  s.false_objects_per_frame = false_objects / n;
  s.overlap_p /= n;
  s.overlap_r /= n;
  s.overlap_f /= n;
  s.boundary_f /= n;
  s.objects_075 /= n;
  s.whole_scene_f /= n;
  s.first_ms_median = Median(first);
  s.total_ms_median = Median(total);
  return s;
}

}  // namespace fovea::eval
