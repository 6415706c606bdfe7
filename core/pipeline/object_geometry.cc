#include "core/pipeline/object_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/scene/hull_candidates.h"

namespace fovea {
namespace {

// The value at `percent` of the values in sorted order (nearest rank);
// reorders `values` (a selection, not a sort).
float Percentile(std::vector<float>& values, float percent) {
  const double rank = percent / 100.0 * (values.size() - 1);
  const auto at = values.begin() + static_cast<ptrdiff_t>(std::lround(rank));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace

absl::Status Validate(const BoxFitOptions& options) {
  if (!(options.trim_percent >= 0.0f && options.trim_percent < 25.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "box_fit.trim_percent must be in [0, 25), got ", options.trim_percent));
  }
  if (!(options.rest_on_support_m >= 0.0f) ||
      !std::isfinite(options.rest_on_support_m)) {
    return absl::InvalidArgumentError(
        absl::StrCat("box_fit.rest_on_support_m must be finite and >= 0, got ",
                     options.rest_on_support_m));
  }
  return absl::OkStatus();
}

absl::StatusOr<ObjectGeometry> FitSupportAlignedBox(
    const std::vector<Eigen::Vector3f>& points, const SupportPlane& plane,
    const BoxFitOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  const Eigen::Vector3f n = plane.normal.normalized();
  if (!n.allFinite() || std::abs(plane.axis_u.dot(n)) > 1e-3f ||
      std::abs(plane.axis_v.dot(n)) > 1e-3f) {
    return absl::FailedPreconditionError(
        "object box: the support plane has no axes");
  }
  std::vector<Eigen::Vector3f> finite;
  finite.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  if (finite.size() < 3) {
    return absl::FailedPreconditionError(
        absl::StrCat("object box: ", finite.size(),
                     " points with depth, at least 3 needed"));
  }
  std::vector<float> heights;
  heights.reserve(finite.size());
  for (const Eigen::Vector3f& p : finite) heights.push_back(plane.Height(p));
  std::vector<float> selected = heights;
  const float low = Percentile(selected, options.trim_percent);
  const float high = Percentile(selected, 100.0f - options.trim_percent);
  std::vector<Eigen::Vector2f> footprint;
  footprint.reserve(finite.size());
  for (size_t i = 0; i < finite.size(); ++i) {
    if (heights[i] < low || heights[i] > high) continue;
    footprint.push_back(plane.ToPlane(finite[i]));
  }
  if (footprint.size() < 3) {
    return absl::FailedPreconditionError(
        "object box: fewer than 3 points left after trimming");
  }
  // The minimum-area rectangle's two side directions; x along the longer.
  // It depends on the footprint's hull only: the points that can be hull
  // vertices give the same rectangle (cv::minAreaRect's hull sorts its
  // points, so their order does not matter).
  const cv::RotatedRect rect = cv::minAreaRect(HullCandidates(footprint));
  cv::Point2f corner[4];
  rect.points(corner);
  Eigen::Vector2f side_a(corner[1].x - corner[0].x, corner[1].y - corner[0].y);
  Eigen::Vector2f side_b(corner[2].x - corner[1].x, corner[2].y - corner[1].y);
  if (side_b.norm() > side_a.norm()) std::swap(side_a, side_b);
  const float length = side_a.norm(), width = side_b.norm();
  Eigen::Vector2f along =
      length > 0.0f ? Eigen::Vector2f(side_a / length) : Eigen::Vector2f(1, 0);
  // One of the two directions, the same for the same footprint.
  if (along.x() < 0.0f || (along.x() == 0.0f && along.y() < 0.0f)) {
    along = -along;
  }
  const float base =
      low <= options.rest_on_support_m ? 0.0f : low;  // stands on the plane
  const float top = std::max(high, base);

  ObjectGeometry g;
  // The point of the plane with plane coordinates (cx, cy): the plane's
  // point nearest the camera, -d n, plus cx u + cy v.
  const Eigen::Vector3f on_plane = -plane.d * n + rect.center.x * plane.axis_u +
                                   rect.center.y * plane.axis_v;
  g.support_origin = on_plane;
  Eigen::Matrix3f support_axes;
  support_axes << plane.axis_u, plane.axis_v, n;
  g.support_orientation = Eigen::Quaternionf(support_axes).normalized();

  const Eigen::Vector3f x = along.x() * plane.axis_u + along.y() * plane.axis_v;
  const Eigen::Vector3f z = n;
  const Eigen::Vector3f y = z.cross(x);
  Eigen::Matrix3f box_axes;
  box_axes << x, y, z;
  g.box.center = on_plane + 0.5f * (base + top) * n;
  g.box.orientation = Eigen::Quaternionf(box_axes).normalized();
  g.box.size = Eigen::Vector3f(length, width, top - base);

  g.box_in_support.center = Eigen::Vector3f(0.0f, 0.0f, 0.5f * (base + top));
  g.box_in_support.orientation = Eigen::Quaternionf(Eigen::AngleAxisf(
      std::atan2(along.y(), along.x()), Eigen::Vector3f::UnitZ()));
  g.box_in_support.size = g.box.size;
  g.height_above_support = top;
  g.footprint_area_m2 = length * width;
  return g;
}

std::vector<Eigen::Vector3f> MaskPoints(const OrganizedCloud& cloud,
                                        const cv::Mat& mask,
                                        const cv::Rect& within) {
  const cv::Rect all(0, 0, mask.cols, mask.rows);
  const cv::Rect box = within.empty() ? all : (within & all);
  std::vector<Eigen::Vector3f> points;
  for (int v = box.y; v < box.br().y; ++v) {
    const uint8_t* in = mask.ptr<uint8_t>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (in[u] == 0 || std::isnan(xyz[u][2])) continue;
      points.emplace_back(xyz[u][0], xyz[u][1], xyz[u][2]);
    }
  }
  return points;
}

std::vector<int> EvenSample(int count, int max_points) {
  std::vector<int> picked;
  if (count <= 0) return picked;
  const int n = max_points > 0 ? std::min(count, max_points) : count;
  picked.reserve(n);
  for (int i = 0; i < n; ++i) {
    picked.push_back(static_cast<int>(static_cast<int64_t>(i) * count / n));
  }
  return picked;
}

std::vector<int> MaskIndices(const cv::Mat& mask, int max_points) {
  std::vector<int> all;
  for (int v = 0; v < mask.rows; ++v) {
    const uint8_t* in = mask.ptr<uint8_t>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (in[u] != 0) all.push_back(v * mask.cols + u);
    }
  }
  std::vector<int> picked;
  for (const int i : EvenSample(static_cast<int>(all.size()), max_points)) {
    picked.push_back(all[i]);
  }
  return picked;
}

}  // namespace fovea
