#include "core/synth/replayed_scene.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"

namespace fovea::synth {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Kinect v1, as KinectV1Noise(): sigma = 1.43e-3 z^2, depth quantised to
// z^2 / (f b) / 8 with a 7.5 cm baseline.
constexpr float kSigmaPerZ2 = 1.43e-3f;
constexpr float kBaselineM = 0.075f;
constexpr float kDisparityStepPx = 0.125f;
constexpr float kEdgeJumpM = 0.03f;
constexpr float kEdgeDropout = 0.3f;
constexpr float kColorSigma = 3.0f;

Eigen::Vector3f Ray(const Intrinsics& k, int u, int v) {
  return {static_cast<float>((u - k.cx) / k.fx),
          static_cast<float>((v - k.cy) / k.fy), 1.0f};
}

// Fresh sensor noise on `frame`: axial, quantised, edge dropouts, colour.
void AddNoise(std::mt19937_64& rng, RgbdFrame& frame) {
  std::normal_distribution<float> unit(0.0f, 1.0f);
  std::uniform_real_distribution<float> coin(0.0f, 1.0f);
  const cv::Mat before = frame.depth.clone();
  const float fb = static_cast<float>(frame.intrinsics.fx) * kBaselineM;
  for (int v = 0; v < frame.depth.rows; ++v) {
    float* z = frame.depth.ptr<float>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      const float z0 = before.at<float>(v, u);
      if (!(z0 > 0.0f)) continue;
      // A depth jump beside this pixel: its edge comes and goes.
      bool edge = false;
      for (int dv = -1; dv <= 1 && !edge; ++dv) {
        for (int du = -1; du <= 1 && !edge; ++du) {
          const int uu = u + du;
          const int vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= before.cols || vv >= before.rows) {
            continue;
          }
          const float n = before.at<float>(vv, uu);
          edge = !(n > 0.0f) || std::abs(n - z0) > kEdgeJumpM;
        }
      }
      if (edge && coin(rng) < kEdgeDropout) {
        z[u] = kNaN;
        continue;
      }
      const float noisy = z0 + kSigmaPerZ2 * z0 * z0 * unit(rng);
      const float step = noisy * noisy / fb * kDisparityStepPx;
      z[u] = step > 0.0f ? std::round(noisy / step) * step : noisy;
    }
  }
  for (int v = 0; v < frame.color.rows; ++v) {
    cv::Vec3b* c = frame.color.ptr<cv::Vec3b>(v);
    for (int u = 0; u < frame.color.cols; ++u) {
      for (int k = 0; k < 3; ++k) {
        c[u][k] = cv::saturate_cast<uint8_t>(c[u][k] + kColorSigma * unit(rng));
      }
    }
  }
}

// `scene` seen from `camera_to_world` (the world being its own camera):
// every point re-projected, the nearest winning; a pixel missed between
// seen neighbours (5 of its 8) takes their median depth.
LabelledFrame Reproject(const LabelledFrame& scene,
                        const Eigen::Isometry3f& camera_to_world) {
  const Intrinsics& k = scene.frame.intrinsics;
  const Eigen::Isometry3f world_to_camera = camera_to_world.inverse();
  const cv::Size size = scene.frame.depth.size();
  LabelledFrame out;
  out.name = scene.name;
  out.frame.intrinsics = k;
  out.frame.depth = cv::Mat(size, CV_32FC1, cv::Scalar(kNaN));
  out.frame.color = cv::Mat(size, CV_8UC3, cv::Scalar(0, 0, 0));
  out.labels = cv::Mat(size, CV_32SC1, cv::Scalar(0));
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const float z = scene.frame.depth.at<float>(v, u);
      if (!(z > 0.0f)) continue;
      const Eigen::Vector3f p = world_to_camera * (Ray(k, u, v) * z);
      if (!(p.z() > 0.0f)) continue;
      const int u2 = static_cast<int>(std::lround(k.fx * p.x() / p.z() + k.cx));
      const int v2 = static_cast<int>(std::lround(k.fy * p.y() / p.z() + k.cy));
      if (u2 < 0 || v2 < 0 || u2 >= size.width || v2 >= size.height) continue;
      float& target = out.frame.depth.at<float>(v2, u2);
      if (target > 0.0f && target <= p.z()) continue;
      target = p.z();
      out.frame.color.at<cv::Vec3b>(v2, u2) =
          scene.frame.color.at<cv::Vec3b>(v, u);
      out.labels.at<int>(v2, u2) = scene.labels.at<int>(v, u);
    }
  }
  // Cracks: the moved camera samples the surface a little apart from the
  // first one, leaving 1-pixel lines unseen. A pixel whose 8 neighbours are
  // mostly seen (5 of them; a disocclusion leaves fewer) takes the
  // neighbour of median depth among them.
  const cv::Mat depth = out.frame.depth.clone();
  const cv::Mat color = out.frame.color.clone();
  const cv::Mat labels = out.labels.clone();
  for (int v = 1; v + 1 < size.height; ++v) {
    for (int u = 1; u + 1 < size.width; ++u) {
      if (depth.at<float>(v, u) > 0.0f) continue;
      std::pair<float, cv::Point> seen[8];
      int n = 0;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const float z = depth.at<float>(v + dv, u + du);
          if (z > 0.0f) seen[n++] = {z, cv::Point(u + du, v + dv)};
        }
      }
      if (n < 5) continue;
      std::nth_element(
          seen, seen + n / 2, seen + n,
          [](const auto& a, const auto& b) { return a.first < b.first; });
      const cv::Point from = seen[n / 2].second;
      out.frame.depth.at<float>(v, u) = seen[n / 2].first;
      out.frame.color.at<cv::Vec3b>(v, u) = color.at<cv::Vec3b>(from);
      out.labels.at<int>(v, u) = labels.at<int>(from);
    }
  }
  return out;
}

// The table's plane n . p + d = 0 (n towards the camera), fitted to its
// labelled points; nullopt when fewer than 100.
std::optional<Eigen::Vector4f> TablePlane(const LabelledFrame& scene) {
  const Intrinsics& k = scene.frame.intrinsics;
  std::vector<Eigen::Vector3f> points;
  for (int v = 0; v < scene.labels.rows; v += 2) {
    for (int u = 0; u < scene.labels.cols; u += 2) {
      const float z = scene.frame.depth.at<float>(v, u);
      if (IsTableLabel(scene.labels.at<int>(v, u)) && z > 0.0f) {
        points.push_back(Ray(k, u, v) * z);
      }
    }
  }
  if (points.size() < 100) return std::nullopt;
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& p : points) mean += p;
  mean /= static_cast<float>(points.size());
  Eigen::Matrix3f scatter = Eigen::Matrix3f::Zero();
  for (const Eigen::Vector3f& p : points) {
    scatter += (p - mean) * (p - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver(scatter);
  Eigen::Vector3f n = solver.eigenvectors().col(0);  // least variance
  if (n.dot(mean) > 0.0f) n = -n;                    // towards the camera
  return Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(mean));
}

// The objects' ids (ObjectId) in the order they are taken away: the one
// reaching highest above the table first.
std::vector<int> RemovalOrder(const LabelledFrame& scene,
                              const Eigen::Vector4f& plane) {
  const Intrinsics& k = scene.frame.intrinsics;
  std::map<int, float> top;
  for (int v = 0; v < scene.labels.rows; ++v) {
    for (int u = 0; u < scene.labels.cols; ++u) {
      const int id = ObjectId(scene.labels.at<int>(v, u));
      const float z = scene.frame.depth.at<float>(v, u);
      if (id == 0 || !(z > 0.0f)) continue;
      const float height = plane.head<3>().dot(Ray(k, u, v) * z) + plane.w();
      auto [it, fresh] = top.emplace(id, height);
      if (!fresh) it->second = std::max(it->second, height);
    }
  }
  std::vector<std::pair<float, int>> order;
  for (const auto& [id, height] : top) order.emplace_back(-height, id);
  std::sort(order.begin(), order.end());
  std::vector<int> ids;
  for (const auto& row : order) ids.push_back(row.second);
  return ids;
}

// Takes the object `id` out of `scene`: its pixels, and the pixels without
// depth beside them (its shadow), become the table where their ray meets
// the table's plane. Their colour is inpainted from the table's pixels
// around alone (not from other objects').
void TakeAway(int id, const Eigen::Vector4f& plane, LabelledFrame& scene) {
  const Intrinsics& k = scene.frame.intrinsics;
  const cv::Mat object = ObjectIdImage(scene.labels) == id;
  cv::Mat freed;
  cv::dilate(object, freed,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
  freed &= object | (scene.labels == 0);
  if (cv::countNonZero(freed) == 0) return;
  const cv::Rect all(0, 0, scene.labels.cols, scene.labels.rows);
  cv::Rect roi = cv::boundingRect(freed);
  roi = cv::Rect(roi.x - 20, roi.y - 20, roi.width + 40, roi.height + 40) & all;
  // Inpainted from the table's pixels only: everything else is "unknown".
  cv::Mat unknown;
  cv::bitwise_not(
      (scene.labels(roi) >= 1) & (scene.labels(roi) <= 9) & ~freed(roi),
      unknown);
  cv::Mat painted;
  cv::inpaint(scene.frame.color(roi), unknown, painted, 5, cv::INPAINT_TELEA);
  for (int v = roi.y; v < roi.y + roi.height; ++v) {
    for (int u = roi.x; u < roi.x + roi.width; ++u) {
      if (freed.at<uint8_t>(v, u) == 0) continue;
      const float along = plane.head<3>().dot(Ray(k, u, v));
      const float z = along == 0.0f ? -1.0f : -plane.w() / along;
      const bool hit = z > 0.0f && z < 10.0f;
      scene.frame.depth.at<float>(v, u) = hit ? z : kNaN;
      scene.labels.at<int>(v, u) = hit ? 1 : 0;
      scene.frame.color.at<cv::Vec3b>(v, u) =
          painted.at<cv::Vec3b>(v - roi.y, u - roi.x);
    }
  }
}

// `labels` with the parts of one object (labels >= 20 of one ObjectId) that
// touch, directly or through each other, within kPartTouchPx given the
// lowest label of them. mOSD labels apart an object's faces across a depth
// edge (a mug's inside and outside, a tin's lid and side), which touch, as
// well as the parts an occluder separates, which lie 8 px or more apart in
// every scene.
constexpr int kPartTouchPx = 2;

cv::Mat TouchingPartsJoined(const cv::Mat& labels) {
  std::map<int, cv::Mat> parts;
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] >= 20 && parts.find(l[u]) == parts.end()) {
        parts.emplace(l[u], labels == l[u]);
      }
    }
  }
  std::map<int, int> root;
  for (const auto& [label, mask] : parts) root[label] = label;
  const auto find = [&root](int label) {
    while (root[label] != label) label = root[label];
    return label;
  };
  const cv::Mat near = cv::getStructuringElement(
      cv::MORPH_RECT, cv::Size(2 * kPartTouchPx + 1, 2 * kPartTouchPx + 1));
  for (auto a = parts.begin(); a != parts.end(); ++a) {
    cv::Mat grown;
    for (auto b = std::next(a); b != parts.end(); ++b) {
      if (ObjectId(b->first) != ObjectId(a->first)) continue;
      if (grown.empty()) cv::dilate(a->second, grown, near);
      if (cv::countNonZero(grown & b->second) == 0) continue;
      const int ra = find(a->first);
      const int rb = find(b->first);
      root[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  cv::Mat out = labels.clone();
  for (int v = 0; v < out.rows; ++v) {
    int* l = out.ptr<int>(v);
    for (int u = 0; u < out.cols; ++u) {
      if (l[u] >= 20) l[u] = find(l[u]);
    }
  }
  return out;
}

// The k-th present part (label >= 20, in label order) relabelled
// 10 * (k + 2), as RenderScene's labels; `ids` gets the parts' labels.
cv::Mat SequenceLabels(const cv::Mat& labels, std::vector<int>& ids) {
  std::map<int, int> present;
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] >= 20) present.emplace(l[u], 0);
    }
  }
  ids.clear();
  for (auto& [label, index] : present) {
    index = 10 * (static_cast<int>(ids.size()) + 2);
    ids.push_back(label);
  }
  cv::Mat out(labels.size(), CV_32SC1, cv::Scalar(0));
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    int* o = out.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      o[u] = l[u] >= 20 ? present[l[u]] : l[u];
    }
  }
  return out;
}

}  // namespace

absl::Span<const NamedValue<ReplayKind>> ReplayKinds() {
  static constexpr NamedValue<ReplayKind> kTable[] = {
      {ReplayKind::kNoise, "noise"},
      {ReplayKind::kShift, "shift"},
      {ReplayKind::kRemove, "remove"},
  };
  return kTable;
}

Sequence ReplayAsSequence(const LabelledFrame& labelled, ReplayKind kind,
                          uint64_t seed, int frames) {
  FOVEA_CHECK(frames >= 2);
  FOVEA_CHECK(labelled.labels.size() == labelled.frame.depth.size());
  LabelledFrame scene = labelled;
  scene.labels = TouchingPartsJoined(labelled.labels);
  std::mt19937_64 rng(seed * 7919 + static_cast<uint64_t>(kind));
  std::uniform_real_distribution<float> phase(0.0f, 2.0f * kPi);
  const float phase_x = phase(rng);
  const float phase_y = phase(rng);
  std::vector<int> order;
  std::optional<Eigen::Vector4f> plane;
  if (kind == ReplayKind::kRemove) {
    plane = TablePlane(scene);
    if (plane) order = RemovalOrder(scene, *plane);
  }
  const int n = static_cast<int>(order.size());

  Sequence sequence;
  sequence.name = absl::StrCat(
      scene.name, "-", AbslView(NameOf(ReplayKinds(), kind)), "-", seed);
  LabelledFrame current = scene;
  current.frame.depth = scene.frame.depth.clone();
  current.frame.color = scene.frame.color.clone();
  current.labels = scene.labels.clone();
  int removed = 0;
  for (int t = 0; t < frames; ++t) {
    SequenceFrame frame;
    LabelledFrame shown;
    switch (kind) {
      case ReplayKind::kNoise:
        break;
      case ReplayKind::kShift: {
        const float s = static_cast<float>(t) / static_cast<float>(frames - 1);
        const Eigen::Vector3f offset(0.03f * std::sin(2.0f * kPi * s + phase_x),
                                     0.02f * std::sin(2.0f * kPi * s + phase_y),
                                     0.01f * std::sin(4.0f * kPi * s));
        // Turned back towards the scene by up to 1.5 degrees.
        const float yaw = -0.026f * offset.x() / 0.03f;
        const float pitch = 0.026f * offset.y() / 0.02f;
        frame.camera_to_world =
            Eigen::Translation3f(offset) *
            Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitY()) *
            Eigen::AngleAxisf(pitch, Eigen::Vector3f::UnitX());
        shown = Reproject(scene, frame.camera_to_world);
        break;
      }
      case ReplayKind::kRemove:
        // Object i of the order goes at frame (i + 1) * frames / (n + 1);
        // the last one stays.
        while (removed + 1 < n && t >= (removed + 1) * frames / (n + 1)) {
          TakeAway(order[removed], *plane, current);
          ++removed;
        }
        break;
    }
    if (kind != ReplayKind::kShift) {
      shown.name = current.name;
      shown.frame.intrinsics = current.frame.intrinsics;
      shown.frame.depth = current.frame.depth.clone();
      shown.frame.color = current.frame.color.clone();
      shown.labels = current.labels.clone();
    }
    AddNoise(rng, shown.frame);
    // A pixel the noise dropped has no label.
    for (int v = 0; v < shown.labels.rows; ++v) {
      for (int u = 0; u < shown.labels.cols; ++u) {
        if (!(shown.frame.depth.at<float>(v, u) > 0.0f)) {
          shown.labels.at<int>(v, u) = 0;
        }
      }
    }
    frame.frame.name = absl::StrCat(sequence.name, "-", t);
    frame.frame.frame = std::move(shown.frame);
    frame.frame.labels = SequenceLabels(shown.labels, frame.object_ids);
    sequence.frames.push_back(std::move(frame));
  }
  return sequence;
}

}  // namespace fovea::synth
