// The grid of SearchSupport and its geometry (support_grid.h): the grid,
// least-squares planes, plane coordinates and hulls, and a plane's
// connected parts on the grid.

#include "core/scene/support_grid.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "core/scene/hull_candidates.h"

namespace fovea::support_internal {
namespace {

// A grid point's area is taken at no more than this grazing angle.
constexpr float kMinCosIncidence = 0.2f;
// Stride of the full-resolution hull's points, pixels.
constexpr int kHullStride = 4;
// Plane parts: neighbours at most this many expected grid steps apart.
constexpr float kPlaneStepFactor = 2.5f;

}  // namespace

void OrientTowardsCamera(Eigen::Vector3f& normal, float& d) {
  if (d < 0.0f) {
    normal = -normal;
    d = -d;
  }
}

float Grid::Area(int i, const Eigen::Vector3f& normal) const {
  const Eigen::Vector3f& q = p[i];
  const float z = q.z();
  const float pixel = (z * stride / static_cast<float>(intrinsics.fx)) *
                      (z * stride / static_cast<float>(intrinsics.fy));
  const float incidence = std::abs(normal.dot(q)) / q.norm();
  return pixel / std::max(incidence, kMinCosIncidence);
}

Grid MakeGrid(const OrganizedCloud& cloud, int columns) {
  Grid grid;
  grid.stride = std::max(1, (cloud.width() + columns - 1) / columns);
  grid.cols = (cloud.width() + grid.stride - 1) / grid.stride;
  grid.rows = (cloud.height() + grid.stride - 1) / grid.stride;
  grid.intrinsics = cloud.intrinsics;
  grid.p.resize(grid.size());
  grid.n.resize(grid.size());
  for (int r = 0; r < grid.rows; ++r) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(r * grid.stride);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(r * grid.stride);
    for (int c = 0; c < grid.cols; ++c) {
      const int u = c * grid.stride;
      const int i = r * grid.cols + c;
      grid.p[i] = {p[u][0], p[u][1], p[u][2]};
      grid.n[i] = {n[u][0], n[u][1], n[u][2]};
    }
  }
  return grid;
}

std::optional<Plane> FitPlane(const Grid& grid,
                              const std::vector<int>& indices) {
  if (indices.size() < 3) return std::nullopt;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d q = grid.p[i].cast<double>();
    sum += q;
    outer += q * q.transpose();
  }
  const double n = static_cast<double>(indices.size());
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Plane plane;
  plane.normal = eig.eigenvectors().col(0).cast<float>().normalized();
  plane.d = -plane.normal.dot(mean.cast<float>());
  OrientTowardsCamera(plane.normal, plane.d);
  if (!plane.normal.allFinite() || !std::isfinite(plane.d)) return std::nullopt;
  return plane;
}

void SetAxes(SupportPlane& plane) {
  // u along the camera x projected into the plane.
  Eigen::Vector3f u =
      Eigen::Vector3f::UnitX() - plane.normal * plane.normal.x();
  if (u.norm() < 1e-3f) {
    u = Eigen::Vector3f::UnitZ() - plane.normal * plane.normal.z();
  }
  plane.axis_u = u.normalized();
  plane.axis_v = plane.normal.cross(plane.axis_u);
}

bool InsideHull(const std::vector<Eigen::Vector2f>& hull,
                const Eigen::Vector2f& q, float margin) {
  if (hull.size() < 3) return false;
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

std::vector<Eigen::Vector2f> ConvexHull(
    const std::vector<Eigen::Vector2f>& points) {
  std::vector<Eigen::Vector2f> hull;
  if (points.size() < 3) return hull;
  const std::vector<cv::Point2f> pts = HullCandidates(points);
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
  if (hull.size() < 3 || std::abs(area) < 1e-9) hull.clear();
  return hull;
}

std::vector<Eigen::Vector2f> HullOfMask(const OrganizedCloud& cloud,
                                        const cv::Mat& mask,
                                        const SupportPlane& plane) {
  std::vector<Eigen::Vector2f> points;
  for (int v = 0; v < cloud.height(); v += kHullStride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const uint8_t* m = mask.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); u += kHullStride) {
      if (!m[u] || std::isnan(p[u][2])) continue;
      points.push_back(plane.ToPlane({p[u][0], p[u][1], p[u][2]}));
    }
  }
  return ConvexHull(points);
}

std::vector<Eigen::Vector2f> HullOfIndices(const Grid& grid,
                                           const SupportPlane& frame,
                                           const std::vector<int>& indices) {
  std::vector<int> first(grid.rows, -1), last(grid.rows, -1);
  for (const int i : indices) {
    const int r = i / grid.cols;
    if (first[r] < 0 || i < first[r]) first[r] = i;
    if (last[r] < 0 || i > last[r]) last[r] = i;
  }
  std::vector<Eigen::Vector2f> points;
  for (int r = 0; r < grid.rows; ++r) {
    if (first[r] < 0) continue;
    points.push_back(frame.ToPlane(grid.p[first[r]]));
    if (last[r] != first[r]) points.push_back(frame.ToPlane(grid.p[last[r]]));
  }
  return ConvexHull(points);
}

std::vector<std::vector<int>> PlaneParts(const Grid& grid, const Plane& plane,
                                         const SupportPlaneOptions& options,
                                         float min_cos,
                                         const std::vector<int>& also,
                                         std::vector<int>* labels_out) {
  std::vector<uint8_t> mask(grid.size(), 0);
  for (int i = 0; i < grid.size(); ++i) {
    mask[i] =
        grid.HasPoint(i) && IsNearInlier(grid, i, plane, options, min_cos);
  }
  for (const int i : also) mask[i] = 1;
  // Neighbours on one surface of the plane are about one grid step apart
  // in 3D (the step at their depth, stretched by the plane's slant to the
  // ray); farther apart, something hid the plane between them (a bowl's
  // bottom and the table beyond its rim).
  const float step_per_z = static_cast<float>(grid.stride / grid.intrinsics.fx);
  std::vector<int> labels;
  const int n = LabelGridComponents(
      grid, mask,
      [&](int i) {
        const Eigen::Vector3f& p = grid.p[i];
        const float incidence = std::max(
            kMinCosIncidence, std::abs(plane.normal.dot(p)) / p.norm());
        const float reach = kPlaneStepFactor * step_per_z * p.z() / incidence;
        return [&grid, p, reach](int j, bool diagonal) {
          const float limit = diagonal ? reach * 1.4142f : reach;
          return (grid.p[j] - p).squaredNorm() <= limit * limit;
        };
      },
      labels);
  std::vector<std::vector<int>> parts(n);
  for (int i = 0; i < grid.size(); ++i) {
    if (labels[i] > 0) parts[labels[i]].push_back(i);
  }
  if (labels_out != nullptr) *labels_out = std::move(labels);
  return parts;
}

}  // namespace fovea::support_internal
