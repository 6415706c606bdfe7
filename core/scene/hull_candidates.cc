#include "core/scene/hull_candidates.h"

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
  double best[kDirections];  // the extremes' projections
  for (int k = 0; k < kDirections; ++k) {
    best[k] = kDx[k] * points[0].x() + kDy[k] * points[0].y();
  }
  for (size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector2f& a = points[i];
    for (int k = 0; k < kDirections; ++k) {
      const double projection = kDx[k] * a.x() + kDy[k] * a.y();
      if (projection > best[k]) {
        best[k] = projection;
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
  // Each edge's start, direction and least cross product inside, once.
  struct Edge {
    Eigen::Vector2d start, along;
    double least_cross;
  };
  std::vector<Edge> edges;
  for (size_t e = 0; polygon.size() >= 3 && e < polygon.size(); ++e) {
    const Eigen::Vector2d& a = polygon[e];
    const Eigen::Vector2d along = polygon[(e + 1) % polygon.size()] - a;
    edges.push_back({a, along, margin * along.norm()});
  }
  std::vector<cv::Point2f> candidates;
  candidates.reserve(points.size());
  for (const Eigen::Vector2f& p : points) {
    bool inside = !edges.empty();
    for (size_t e = 0; inside && e < edges.size(); ++e) {
      const Edge& edge = edges[e];
      const double cross = edge.along.x() * (p.y() - edge.start.y()) -
                           edge.along.y() * (p.x() - edge.start.x());
      inside = cross > edge.least_cross;
    }
    if (!inside) candidates.emplace_back(p.x(), p.y());
  }
  return candidates;
}

}  // namespace fovea
