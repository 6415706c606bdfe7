// The tracker's look at each frame (tracker.h): what changed since the
// frame last segmented, whether the camera is still, the mean of a still
// period, and the segmentation itself: of the whole frame, on the support
// kept while it fits, or of only the region that changed.

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "core/base/status_macros.h"
#include "core/frame/sensor_model.h"
#include "core/track/object_ops.h"
#include "core/track/region.h"
#include "core/track/tracker.h"

namespace fovea {

void Tracker::AverageInto(const cv::Mat& depth, cv::Mat& mean, cv::Mat& count) {
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    float* m = mean.ptr<float>(v);
    uint8_t* n = count.ptr<uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!(z[u] > 0.0f && std::isfinite(z[u]))) continue;
      ++n[u];
      m[u] = n[u] == 1 ? z[u] : m[u] + (z[u] - m[u]) / static_cast<float>(n[u]);
    }
  }
}

namespace {

// Noise changes single pixels and the rims of depth edges (dropouts come
// and go there); a real change is a region: what survives an opening.
void KeepChangedRegions(const cv::Mat& changed, cv::Mat& regions) {
  cv::morphologyEx(changed, regions, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
}

}  // namespace

bool Tracker::DepthChanged(float z, float z0) const {
  return std::abs(z - z0) >
         std::max(options_.change_min_m,
                  options_.change_sigmas * sensor_.DepthSigma(z0));
}

double Tracker::ChangedFraction(const RgbdFrame& frame,
                                cv::Mat& changed) const {
  const bool colors = !frame.color.empty() && !reference_.color.empty() &&
                      frame.color.size() == reference_.color.size() &&
                      frame.color.type() == CV_8UC3 &&
                      reference_.color.type() == CV_8UC3;
  changed = cv::Mat(frame.depth.size(), CV_8UC1, cv::Scalar(0));
  int64_t valid = 0;
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* z = frame.depth.ptr<float>(v);
    const float* z0 = reference_.depth.ptr<float>(v);
    const cv::Vec3b* c = colors ? frame.color.ptr<cv::Vec3b>(v) : nullptr;
    const cv::Vec3b* c0 = colors ? reference_.color.ptr<cv::Vec3b>(v) : nullptr;
    uint8_t* out = changed.ptr<uint8_t>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      const bool has = z[u] > 0.0f;  // false for NaN
      const bool had = z0[u] > 0.0f;
      if (!has && !had) continue;
      ++valid;
      // Depth that came or went counts as a change: an object placed on a
      // dark table, or taken away, may show as exactly that.
      bool moved = has != had || DepthChanged(z[u], z0[u]);
      if (!moved && colors) {
        for (int k = 0; k < 3; ++k) {
          moved |= std::abs(static_cast<int>(c[u][k]) - c0[u][k]) >
                   options_.color_change;
        }
      }
      out[u] = moved ? 255 : 0;
    }
  }
  KeepChangedRegions(changed, changed);
  return valid == 0 ? 1.0
                    : static_cast<double>(cv::countNonZero(changed)) / valid;
}

cv::Mat Tracker::ChangedSeenFrom(const RgbdFrame& frame,
                                 const Eigen::Isometry3f& pose,
                                 const cv::Rect& area) const {
  // Each pixel with depth within `area` (grown by the opening's reach, so
  // that the opening gives within `area` what it would on the whole frame)
  // is moved into the last view: it changed when no depth was seen there,
  // or a different one. A pixel without depth now tells nothing.
  cv::Mat changed(frame.depth.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect grown =
      Grown(area, 4) & cv::Rect(0, 0, frame.depth.cols, frame.depth.rows);
  if (grown.empty()) return changed;
  cv::Mat local(grown.size(), CV_8UC1, cv::Scalar(0));  // `grown`'s pixels
  const Eigen::Isometry3f to_last = reference_pose_->inverse() * pose;
  const Intrinsics& now = frame.intrinsics;
  const Intrinsics& last = reference_.intrinsics;
  for (int v = grown.y; v < grown.y + grown.height; ++v) {
    const float* z = frame.depth.ptr<float>(v);
    uint8_t* out = local.ptr<uint8_t>(v - grown.y);
    for (int u = grown.x; u < grown.x + grown.width; ++u) {
      if (!(z[u] > 0.0f && std::isfinite(z[u]))) continue;
      const Eigen::Vector3f p =
          to_last * Eigen::Vector3f(
                        static_cast<float>((u - now.cx) / now.fx) * z[u],
                        static_cast<float>((v - now.cy) / now.fy) * z[u], z[u]);
      bool moved = true;
      if (p.z() > 0.0f) {
        const long x = std::lround(last.fx * p.x() / p.z() + last.cx);
        const long y = std::lround(last.fy * p.y() / p.z() + last.cy);
        if (x >= 0 && y >= 0 && x < reference_.depth.cols &&
            y < reference_.depth.rows) {
          const float z0 = reference_.depth.at<float>(static_cast<int>(y),
                                                      static_cast<int>(x));
          if (z0 > 0.0f) moved = DepthChanged(p.z(), z0);
        }
      }
      out[u - grown.x] = moved ? 255 : 0;
    }
  }
  KeepChangedRegions(local, local);
  const cv::Rect inside = area & grown;
  local(inside - grown.tl()).copyTo(changed(inside));
  return changed;
}

bool Tracker::CameraStill(const std::optional<Eigen::Isometry3f>& pose) const {
  if (pose.has_value() != reference_pose_.has_value()) return false;
  if (!pose) return true;  // the pixels decide
  const Eigen::Isometry3f delta = reference_pose_->inverse() * *pose;
  const float angle = Eigen::AngleAxisf(delta.rotation()).angle();
  return delta.translation().norm() <= options_.still_m &&
         std::abs(angle) <= options_.still_rad;
}

absl::StatusOr<bool> Tracker::Segment(
    const RgbdFrame& frame, IncrementalOptions segment,
    const std::optional<Eigen::Isometry3f>& pose, double changed_fraction,
    std::vector<SegmentedObject>& found, const InterruptCheck& interrupt) {
  std::optional<SupportPlane> support;
  SegmentSinks sinks;
  sinks.support = [&support](const SupportPlane& plane) {
    support = plane;
    return absl::OkStatus();
  };
  sinks.object = [&found](SegmentedObject object) {
    found.push_back(std::move(object));
    return absl::OkStatus();
  };
  std::optional<Eigen::Vector4f>& hint = segment.detect.scene.support.plane;
  const bool asked = hint.has_value();
  bool kept = false;
  if (!asked && options_.reuse_support && support_ &&
      (pose || changed_fraction <= options_.reuse_support_changed)) {
    hint = SupportInCamera(pose);
    kept = true;
  }
  absl::Status status =
      RunSegmentIncremental(frame, segment, relation_svm_, sinks, interrupt)
          .status();
  const bool fits =
      status.ok() && support.has_value() &&
      support->inlier_count >= options_.support_fit * support_inliers_;
  if (kept && (status.ok() ? !fits : absl::IsNotFound(status))) {
    // It no longer fits (or has nothing on it): search afresh.
    found.clear();
    support.reset();
    hint.reset();
    kept = false;
    status =
        RunSegmentIncremental(frame, segment, relation_svm_, sinks, interrupt)
            .status();
  }
  FOVEA_RETURN_IF_ERROR(status);
  if (!support.has_value()) {
    support_.reset();
    return kept;
  }
  if (!kept) support_inliers_ = support->inlier_count;
  // Kept in the world: n_w = R n_c, d_w = d_c - n_w . t.
  Eigen::Vector4f plane(support->normal.x(), support->normal.y(),
                        support->normal.z(), support->d);
  if (pose) {
    plane.head<3>() = pose->linear() * support->normal;
    plane[3] = support->d - plane.head<3>().dot(pose->translation());
  }
  support_ = plane;
  return kept;
}

Eigen::Vector4f Tracker::SupportInCamera(
    const std::optional<Eigen::Isometry3f>& pose) const {
  // The world's plane in this camera: n_c = R^T n_w, d_c = d_w + n_w . t.
  Eigen::Vector4f plane = *support_;
  if (pose) {
    plane.head<3>() = pose->linear().transpose() * support_->head<3>();
    plane[3] = (*support_)[3] + support_->head<3>().dot(pose->translation());
  }
  return plane;
}

void Tracker::JoinAsVoted(const std::vector<Track>& tracks,
                          const cv::Mat& depth,
                          std::vector<SegmentedObject>& found) {
  std::vector<std::vector<SegmentedObject>> cuts(1);
  for (const Track& t : tracks) {
    if (t.last_seen_frame == frame_index_ - 1) {
      cuts[0].push_back(OutlineOf(t.object));
    }
  }
  for (std::vector<SegmentedObject>& vote : votes_) {
    cuts.push_back(std::move(vote));
  }
  votes_.clear();
  // Not two objects one occludes (4-neighbours across their border).
  const auto may_join = [&](const SegmentedObject& a,
                            const SegmentedObject& b) {
    return !DepthEdgeBetween(a, b, depth, 1);
  };
  JoinWhereMostHoldAsOne(cuts, may_join, found);
}

bool Tracker::DepthEdgeBetween(const SegmentedObject& a,
                               const SegmentedObject& b, const cv::Mat& depth,
                               int reach) const {
  const BorderJumps border = CountBorderJumps(
      a, b, depth, [this](float z, float z2) { return DepthChanged(z, z2); },
      reach);
  return 2 * border.jumps > border.pairs;
}

absl::StatusOr<bool> Tracker::SegmentRegion(
    const RgbdFrame& frame, IncrementalOptions segment,
    const std::optional<Eigen::Isometry3f>& pose, const cv::Rect& region,
    const cv::Mat& changed, const std::vector<Track>& tracks,
    std::vector<SegmentedObject>& found, const InterruptCheck& interrupt) {
  const cv::Size size = frame.depth.size();
  const RgbdFrame crop = CropFrame(frame, region);
  // As the whole frame would be: the crop's own principal point would
  // choose another noise model and range, its width no reduction, and the
  // support's smallest area is the whole frame's share of it.
  SceneOptions& scene = segment.detect.scene;
  scene.sensor = NoiseKind(scene.sensor, frame.intrinsics);
  if (!(scene.workspace.min_depth_m > 0.0f)) {
    scene.workspace.min_depth_m = sensor_.min_range_m;
  }
  if (!(scene.workspace.max_depth_m > 0.0f)) {
    scene.workspace.max_depth_m = sensor_.max_range_m;
  }
  if (frame.width() > scene.processing_width) {
    scene.processing_width =
        std::clamp(static_cast<int>(
                       std::lround(static_cast<double>(scene.processing_width) *
                                   region.width / frame.width())),
                   kMinProcessingWidth, kMaxProcessingWidth);
  }
  if (!scene.support.plane) scene.support.plane = SupportInCamera(pose);
  segment.detect.support_plane.min_candidate_area_m2 *=
      static_cast<float>(region.area()) / static_cast<float>(size.area());
  if (!segment.change.empty()) segment.change = segment.change(region).clone();

  std::vector<SegmentedObject> inside;
  SegmentSinks sinks;
  sinks.object = [&inside](SegmentedObject object) {
    inside.push_back(std::move(object));
    return absl::OkStatus();
  };
  const absl::Status status =
      RunSegmentIncremental(crop, segment, relation_svm_, sinks, interrupt)
          .status();
  if (absl::IsNotFound(status)) return false;  // no support in view there
  FOVEA_RETURN_IF_ERROR(status);
  for (SegmentedObject& o : inside) {
    if (ReachesInnerBorder(o.box, region, size)) return false;
    ObjectToFrame(region, size, o);
  }
  // An object of the last frame taken into the region whose pixels did not
  // change is there still: when the cut of the region misses it, the cut
  // is not to be trusted (the support seen through the region ends
  // short of it, say).
  for (const Track& t : tracks) {
    if (t.last_seen_frame != frame_index_ - 1 ||
        (t.object.box & region).empty()) {
      continue;
    }
    if (OverlapWithHeld(changed, t.object) * 2 >= t.object.area) continue;
    int covered = 0;
    for (const SegmentedObject& o : inside) {
      covered += OverlapWithHeld(o.mask, t.object);
    }
    if (covered * 2 < t.object.area) return false;
  }
  // As many as the whole frame's cut may give (max_objects): what changed
  // first, then the kept ones.
  const size_t room = segment.max_objects > 0
                          ? static_cast<size_t>(segment.max_objects)
                          : std::numeric_limits<size_t>::max();
  for (SegmentedObject& o : inside) found.push_back(std::move(o));
  for (const Track& t : tracks) {
    if (found.size() >= room) break;
    if (t.last_seen_frame != frame_index_ - 1 ||
        !(t.object.box & region).empty()) {
      continue;
    }
    SegmentedObject kept = t.object;
    kept.mask = MaskAtSize(t.object, size);
    found.push_back(std::move(kept));
  }
  for (size_t j = 0; j < found.size(); ++j) {
    found[j].index = static_cast<int>(j);
  }
  return true;
}

}  // namespace fovea
