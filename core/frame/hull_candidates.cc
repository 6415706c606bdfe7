#include "core/frame/hull_candidates.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace fovea {

std::vector<cv::Point2f> HullCandidates(
    const std::vector<Eigen::Vector2f>& points) {
  if (points.empty()) return {};
  constexpr int kDirections = 8;
  // Direction k is (cos, sin) of k * 45 degrees, unnormalised.
  constexpr double kDx[kDirections] = {1, 1, 0, -1, -1, -1, 0, 1};
  constexpr double kDy[kDirections] = {0, 1, 1, 1, 0, -1, -1, -1};
  size_t extreme[kDirections] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (size_t i = 1; i < points.size(); ++i) {
    for (int k = 0; k < kDirections; ++k) {
      const Eigen::Vector2f& a = points[i];
      const Eigen::Vector2f& b = points[extreme[k]];
      if (kDx[k] * a.x() + kDy[k] * a.y() > kDx[k] * b.x() + kDy[k] * b.y()) {
        extreme[k] = i;
      }
    }
  }
  std::vector<Eigen::Vector2d> polygon;  // counter-clockwise
  for (int k = 0; k < kDirections; ++k) {
    const Eigen::Vector2d q = points[extreme[k]].cast<double>();
    if (polygon.empty() || q != polygon.back()) polygon.push_back(q);
  }
  while (polygon.size() > 1 && polygon.front() == polygon.back()) {
    polygon.pop_back();
  }
  double scale = 0.0;
  for (const Eigen::Vector2d& q : polygon) {
    scale = std::max({scale, std::abs(q.x()), std::abs(q.y())});
  }
  // Float rounding of coordinates of size `scale`, with room to spare.
  const double margin = 1e-5 * std::max(scale, 1.0);
  std::vector<cv::Point2f> candidates;
  candidates.reserve(points.size());
  for (const Eigen::Vector2f& p : points) {
    bool inside = polygon.size() >= 3;
    for (size_t e = 0; inside && e < polygon.size(); ++e) {
      const Eigen::Vector2d& a = polygon[e];
      const Eigen::Vector2d edge = polygon[(e + 1) % polygon.size()] - a;
      const double cross =
          edge.x() * (p.y() - a.y()) - edge.y() * (p.x() - a.x());
      inside = cross > margin * edge.norm();
    }
    if (!inside) candidates.emplace_back(p.x(), p.y());
  }
  return candidates;
}

}  // namespace fovea
