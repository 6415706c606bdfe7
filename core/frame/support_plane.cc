#include "core/frame/support_plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace fovea {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// Hypotheses are first scored on at most this many samples, then the best
// few are re-scored on all samples (preemptive RANSAC, Nister 2003).
constexpr int kQuickScoreSamples = 1500;
constexpr int kFullScoreCandidates = 8;
// Pixel stride for the least-squares refinement.
constexpr int kRefineStride = 2;
// Pixel stride for the convex hull's points (the hull is found to within
// this many pixels, a few millimetres at table range).
constexpr int kHullStride = 4;
// The connected components are labelled on every kComponentStride-th row
// and column; a full-resolution inlier belongs to the table when its
// block's sample does.
constexpr int kComponentStride = 2;

struct Sample {
  Eigen::Vector3f p;
  Eigen::Vector3f n;
};

struct PlaneHypothesis {
  Eigen::Vector3f normal;
  float d = 0.0f;
  int support = 0;
};

std::vector<Sample> Subsample(const OrganizedCloud& cloud, int stride) {
  std::vector<Sample> samples;
  samples.reserve(static_cast<size_t>(cloud.width() / stride + 1) *
                  (cloud.height() / stride + 1));
  for (int v = 0; v < cloud.height(); v += stride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); u += stride) {
      if (std::isnan(p[u][2]) || std::isnan(n[u][2])) continue;
      samples.push_back(
          {{p[u][0], p[u][1], p[u][2]}, {n[u][0], n[u][1], n[u][2]}});
    }
  }
  return samples;
}

// Orients the normal towards the camera (origin): the camera is on the
// positive side, n . 0 + d > 0.
void OrientTowardsCamera(Eigen::Vector3f& normal, float& d) {
  if (d < 0.0f) {
    normal = -normal;
    d = -d;
  }
}

int CountSupport(const PlaneHypothesis& h, const std::vector<Sample>& samples,
                 size_t limit, float max_dist, float min_cos) {
  int support = 0;
  const size_t n = std::min(limit, samples.size());
  for (size_t i = 0; i < n; ++i) {
    const Sample& s = samples[i];
    if (std::abs(h.normal.dot(s.p) + h.d) <= max_dist &&
        std::abs(h.normal.dot(s.n)) >= min_cos) {
      ++support;
    }
  }
  return support;
}

bool FaceUp(const Eigen::Vector3f& normal, float max_tilt_deg) {
  // Camera "up" is -y in the camera frame.
  return -normal.y() >= std::cos(max_tilt_deg * kDegToRad) - 1e-6f;
}

// Least-squares plane (PCA) through the points within `max_dist` of the
// hypothesis whose normals agree, on a stride-`kRefineStride` grid.
bool RefinePlane(const OrganizedCloud& cloud, float max_dist, float min_cos,
                 Eigen::Vector3f& normal, float& d) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int count = 0;
  for (int v = 0; v < cloud.height(); v += kRefineStride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); u += kRefineStride) {
      if (std::isnan(p[u][2]) || std::isnan(n[u][2])) continue;
      const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
      const Eigen::Vector3f m(n[u][0], n[u][1], n[u][2]);
      if (std::abs(normal.dot(q) + d) > max_dist ||
          std::abs(normal.dot(m)) < min_cos) {
        continue;
      }
      const Eigen::Vector3d qd = q.cast<double>();
      sum += qd;
      outer += qd * qd.transpose();
      ++count;
    }
  }
  if (count < 3) return false;
  const Eigen::Vector3d mean = sum / count;
  const Eigen::Matrix3d cov = outer / count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3f refined = eig.eigenvectors().col(0).cast<float>();
  if (refined.dot(normal) < 0.0f) refined = -refined;
  normal = refined.normalized();
  d = -normal.dot(mean.cast<float>());
  OrientTowardsCamera(normal, d);
  return true;
}

// Inlier mask at full resolution, reduced to its largest 8-connected
// component.
cv::Mat LargestInlierComponent(const OrganizedCloud& cloud,
                               const Eigen::Vector3f& normal, float d,
                               float max_dist, float min_cos, int& count) {
  cv::Mat mask(cloud.height(), cloud.width(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    uint8_t* m = mask.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (std::isnan(p[u][2])) continue;
      const float dist = normal.x() * p[u][0] + normal.y() * p[u][1] +
                         normal.z() * p[u][2] + d;
      if (std::abs(dist) > max_dist) continue;
      // Points without a normal (edges, noise) count when they are close.
      if (!std::isnan(n[u][2]) &&
          std::abs(normal.x() * n[u][0] + normal.y() * n[u][1] +
                   normal.z() * n[u][2]) < min_cos) {
        continue;
      }
      m[u] = 255;
    }
  }
  cv::Mat coarse;
  cv::resize(mask, coarse,
             cv::Size((mask.cols + kComponentStride - 1) / kComponentStride,
                      (mask.rows + kComponentStride - 1) / kComponentStride),
             0, 0, cv::INTER_NEAREST);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(coarse, labels, stats,
                                                 centroids, 8, CV_32S);
  int best = 0, best_area = 0;
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area > best_area) {
      best_area = area;
      best = i;
    }
  }
  count = 0;
  for (int v = 0; v < mask.rows; ++v) {
    uint8_t* m = mask.ptr<uint8_t>(v);
    const int* l =
        labels.ptr<int>(std::min(v / kComponentStride, labels.rows - 1));
    for (int u = 0; u < mask.cols; ++u) {
      if (!m[u]) continue;
      if (best == 0 ||
          l[std::min(u / kComponentStride, labels.cols - 1)] != best) {
        m[u] = 0;
      } else {
        ++count;
      }
    }
  }
  return mask;
}

std::vector<Eigen::Vector2f> HullInPlane(const OrganizedCloud& cloud,
                                         const cv::Mat& inliers,
                                         const SupportPlane& plane) {
  std::vector<cv::Point2f> pts;
  for (int v = 0; v < cloud.height(); v += kHullStride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const uint8_t* m = inliers.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); u += kHullStride) {
      if (!m[u]) continue;
      const Eigen::Vector2f q = plane.ToPlane({p[u][0], p[u][1], p[u][2]});
      pts.emplace_back(q.x(), q.y());
    }
  }
  std::vector<Eigen::Vector2f> hull;
  if (pts.size() < 3) return hull;
  std::vector<cv::Point2f> h;
  cv::convexHull(pts, h, /*clockwise=*/false);
  hull.reserve(h.size());
  for (const cv::Point2f& q : h) hull.emplace_back(q.x, q.y);
  // Make sure the order is counter-clockwise (positive signed area).
  double area = 0.0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f& b = hull[(i + 1) % hull.size()];
    area +=
        static_cast<double>(a.x()) * b.y() - static_cast<double>(b.x()) * a.y();
  }
  if (area < 0.0) std::reverse(hull.begin(), hull.end());
  return hull;
}

}  // namespace

bool SupportPlane::ProjectsInsideHull(const Eigen::Vector3f& p,
                                      float margin) const {
  if (hull.size() < 3 || !p.allFinite()) return false;
  const Eigen::Vector2f q = ToPlane(p);
  const float margin2 = margin * margin;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f edge = hull[(i + 1) % hull.size()] - a;
    // cross = |edge| times the signed distance of q from the edge's line,
    // positive inside (the hull is counter-clockwise). Inside by `margin`:
    // cross >= margin |edge|, compared squared to avoid a square root.
    const float cross = edge.x() * (q.y() - a.y()) - edge.y() * (q.x() - a.x());
    if (!(cross >= 0.0f)) return false;  // NaN is outside too
    if (margin > 0.0f && cross * cross < margin2 * edge.squaredNorm()) {
      return false;
    }
  }
  return true;
}

absl::Status Validate(const SupportPlaneOptions& options) {
  if (!(options.inlier_distance > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("support_plane.inlier_distance must be > 0, got ",
                     options.inlier_distance));
  }
  if (!(options.max_normal_angle_deg > 0.0f &&
        options.max_normal_angle_deg <= 90.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support_plane.max_normal_angle_deg must be in (0, 90], got ",
        options.max_normal_angle_deg));
  }
  if (options.ransac_iterations < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("support_plane.ransac_iterations must be >= 1, got ",
                     options.ransac_iterations));
  }
  if (options.subsample_stride < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("support_plane.subsample_stride must be >= 1, got ",
                     options.subsample_stride));
  }
  if (!(options.max_tilt_from_camera_up_deg > 0.0f &&
        options.max_tilt_from_camera_up_deg <= 180.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support_plane.max_tilt_from_camera_up_deg must be in (0, 180], got ",
        options.max_tilt_from_camera_up_deg));
  }
  if (!(options.min_inlier_fraction >= 0.0f &&
        options.min_inlier_fraction < 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support_plane.min_inlier_fraction must be in [0, 1), got ",
        options.min_inlier_fraction));
  }
  return absl::OkStatus();
}

absl::StatusOr<SupportPlane> FindSupportPlane(
    const OrganizedCloud& cloud, const SupportPlaneOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  std::vector<Sample> samples = Subsample(cloud, options.subsample_stride);
  if (samples.size() < 3) {
    return absl::NotFoundError(
        "support plane: fewer than 3 points with normals");
  }
  std::mt19937 rng(options.seed);
  // Shuffle once so that the first kQuickScoreSamples are a random subset.
  std::shuffle(samples.begin(), samples.end(), rng);
  const float min_cos = std::cos(options.max_normal_angle_deg * kDegToRad);
  std::uniform_int_distribution<size_t> pick(0, samples.size() - 1);

  std::vector<PlaneHypothesis> hypotheses;
  hypotheses.reserve(options.ransac_iterations);
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const Sample& a = samples[pick(rng)];
    const Sample& b = samples[pick(rng)];
    const Sample& c = samples[pick(rng)];
    Eigen::Vector3f normal = (b.p - a.p).cross(c.p - a.p);
    const float norm = normal.norm();
    if (!(norm > 1e-9f)) continue;
    normal /= norm;
    float d = -normal.dot(a.p);
    OrientTowardsCamera(normal, d);
    if (!FaceUp(normal, options.max_tilt_from_camera_up_deg)) continue;
    PlaneHypothesis h{normal, d, 0};
    h.support = CountSupport(h, samples, kQuickScoreSamples,
                             options.inlier_distance, min_cos);
    hypotheses.push_back(h);
  }
  if (hypotheses.empty()) {
    return absl::NotFoundError(
        "support plane: no plane facing the camera's up direction");
  }
  const size_t keep = std::min<size_t>(kFullScoreCandidates, hypotheses.size());
  std::partial_sort(hypotheses.begin(), hypotheses.begin() + keep,
                    hypotheses.end(),
                    [](const PlaneHypothesis& x, const PlaneHypothesis& y) {
                      return x.support > y.support;
                    });
  PlaneHypothesis best = hypotheses[0];
  best.support = -1;
  for (size_t i = 0; i < keep; ++i) {
    PlaneHypothesis h = hypotheses[i];
    h.support = CountSupport(h, samples, samples.size(),
                             options.inlier_distance, min_cos);
    if (h.support > best.support) best = h;
  }
  const int min_support =
      static_cast<int>(std::ceil(options.min_inlier_fraction * samples.size()));
  if (best.support < std::max(min_support, 3)) {
    return absl::NotFoundError(
        absl::StrCat("support plane: the best plane has ", best.support, " of ",
                     samples.size(), " sampled points, fewer than the ",
                     min_support, " required"));
  }

  SupportPlane plane;
  plane.normal = best.normal;
  plane.d = best.d;
  // Two rounds: each refit can admit points the coarse plane missed.
  for (int round = 0; round < 2; ++round) {
    RefinePlane(cloud, options.inlier_distance, min_cos, plane.normal, plane.d);
  }
  int inlier_count = 0;
  const cv::Mat inliers =
      LargestInlierComponent(cloud, plane.normal, plane.d,
                             options.inlier_distance, min_cos, inlier_count);
  return SupportPlaneFromInliers(cloud, plane.normal, plane.d, inliers);
}

absl::StatusOr<SupportPlane> SupportPlaneFromInliers(
    const OrganizedCloud& cloud, const Eigen::Vector3f& normal, float d,
    const cv::Mat& inliers) {
  const float norm = normal.norm();
  if (!(norm > 0.0f) || !std::isfinite(norm) || !std::isfinite(d)) {
    return absl::InvalidArgumentError(
        "support plane: the normal must be finite and non-zero");
  }
  if (inliers.type() != CV_8UC1 || inliers.rows != cloud.height() ||
      inliers.cols != cloud.width()) {
    return absl::InvalidArgumentError(
        "support plane: inliers must be CV_8UC1 of the cloud's size");
  }
  SupportPlane plane;
  plane.normal = normal / norm;
  plane.d = d / norm;
  OrientTowardsCamera(plane.normal, plane.d);
  plane.inliers = inliers;
  plane.inlier_count = cv::countNonZero(inliers);
  // Axes: u along the camera x projected into the plane.
  Eigen::Vector3f u =
      Eigen::Vector3f::UnitX() - plane.normal * plane.normal.x();
  if (u.norm() < 1e-3f)
    u = Eigen::Vector3f::UnitZ() - plane.normal * plane.normal.z();
  plane.axis_u = u.normalized();
  plane.axis_v = plane.normal.cross(plane.axis_u);
  plane.hull = HullInPlane(cloud, plane.inliers, plane);
  if (plane.hull.size() < 3) {
    return absl::NotFoundError("support plane: inliers have no 2D extent");
  }
  return plane;
}

}  // namespace fovea
