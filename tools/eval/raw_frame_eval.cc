#include "tools/eval/raw_frame_eval.h"

#include <filesystem>
#include <optional>

#include "absl/strings/str_cat.h"
#include "core/frame/osd_pcd.h"
#include "tools/eval/realsense_frames.h"
#include "tools/eval/stats.h"

namespace fovea::eval {
namespace {

constexpr int kMinObjectPixels = 50;
constexpr char kColorSuffix[] = "_color.png";

RawFrameScore Score(const cv::Mat& labels, const SceneRun& run) {
  RawFrameScore s;
  s.total_ms = run.total_ms;
  s.masks = static_cast<int>(run.masks.size());
  cv::Mat ids(labels.size(), CV_32SC1);
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      ids.at<int>(v, u) = ObjectId(labels.at<int>(v, u));
    }
  }
  const cv::Mat objects = ids > 0;
  const cv::Mat masked = run.segments >= 0;
  const int on = cv::countNonZero(masked & objects);
  const int mask_pixels = cv::countNonZero(masked);
  const int object_pixels = cv::countNonZero(objects);
  s.precision = mask_pixels > 0 ? static_cast<double>(on) / mask_pixels : 1.0;
  s.recall = object_pixels > 0 ? static_cast<double>(on) / object_pixels : 1.0;
  for (const SeededMask& m : run.masks) {
    s.false_objects +=
        2 * cv::countNonZero(m.mask & objects) < cv::countNonZero(m.mask);
  }
  s.uois = ScoreUois(ids, run.segments, kMinObjectPixels);
  return s;
}

}  // namespace

absl::StatusOr<std::vector<RawFrameResult>> EvaluateRawFrames(
    const std::string& osd_dir, const SceneRunOptions& options) {
  namespace fs = std::filesystem;
  const fs::path frames = fs::path(osd_dir) / "frames";
  std::vector<std::string> names;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(frames, ec)) {
    const std::string file = e.path().filename().string();
    const size_t n = file.size(), k = sizeof(kColorSuffix) - 1;
    if (n > k && file.compare(n - k, k, kColorSuffix) == 0) {
      const std::string name = file.substr(0, n - k);
      if (fs::exists(fs::path(osd_dir) / "learn" / (name + ".pcd"))) {
        names.push_back(name);
      }
    }
  }
  if (names.empty()) {
    return absl::NotFoundError(absl::StrCat(
        "raw frames: no frames/<scene>_color.png with learn/<scene>.pcd in ",
        osd_dir));
  }
  std::sort(names.begin(), names.end());
  std::vector<RawFrameResult> results;
  for (const std::string& name : names) {
    absl::StatusOr<LabelledFrame> cropped =
        LoadOsdPcd((fs::path(osd_dir) / "learn" / (name + ".pcd")).string());
    if (!cropped.ok()) return InScene(name, cropped.status());
    std::optional<RgbdFrame> read =
        ReadRawFrame(frames, name, cropped->frame.intrinsics);
    if (!read || read->color.size() != cropped->labels.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": raw frame missing or not the scene's size"));
    }
    LabelledFrame raw;
    raw.name = name + "-raw";
    raw.frame = *std::move(read);
    raw.labels = cropped->labels;
    RawFrameResult r;
    r.name = name;
    absl::StatusOr<SceneRun> on_cropped = RunOnScene(*cropped, options);
    if (!on_cropped.ok()) return InScene(name, on_cropped.status());
    absl::StatusOr<SceneRun> on_raw = RunOnScene(raw, options);
    if (!on_raw.ok()) return InScene(raw.name, on_raw.status());
    r.cropped = Score(cropped->labels, *on_cropped);
    r.raw = Score(cropped->labels, *on_raw);
    results.push_back(r);
  }
  return results;
}

}  // namespace fovea::eval
