#include "core/scene/hull_lookup.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/scene/support_grid.h"

namespace fovea {

HullLookup::HullLookup(const SupportPlane& plane, float margin)
    : axis_u_(plane.axis_u),
      axis_v_(plane.axis_v),
      hull_(plane.hull),
      margin_(margin) {
  if (hull_.size() < 3) return;  // nothing is inside; Contains says so
  double lo_x = hull_[0].x(), hi_x = lo_x, lo_y = hull_[0].y(), hi_y = lo_y;
  for (const Eigen::Vector2f& q : hull_) {
    lo_x = std::min<double>(lo_x, q.x());
    hi_x = std::max<double>(hi_x, q.x());
    lo_y = std::min<double>(lo_y, q.y());
    hi_y = std::max<double>(hi_y, q.y());
  }
  const double span = std::max({hi_x - lo_x, hi_y - lo_y, 1e-3});
  cell_ = span / kCells;
  // One cell of border all round, so the cells at the hull's extremes are
  // decided by the grid too.
  x0_ = lo_x - cell_;
  y0_ = lo_y - cell_;
  cols_ = static_cast<int>(std::ceil((hi_x - lo_x) / cell_)) + 2;
  rows_ = static_cast<int>(std::ceil((hi_y - lo_y) / cell_)) + 2;
  cells_.assign(static_cast<size_t>(cols_) * rows_, kStraddles);
  // Each edge's cross product (|edge| times the signed distance from its
  // line, positive inside) is linear, A x + B y + C, so over a row of cells
  // (a band of y) each edge bounds the x of the cells wholly inside it by
  // one half-line, and of those wholly outside it by another: per row, the
  // cells inside every edge form one interval, and those outside some edge
  // lie left or right of two bounds.
  struct Edge {
    double A, B, C, inside_above, outside_below;
  };
  std::vector<Edge> edges;
  for (size_t e = 0; e < hull_.size(); ++e) {
    const Eigen::Vector2d a = hull_[e].cast<double>();
    const Eigen::Vector2d edge =
        hull_[(e + 1) % hull_.size()].cast<double>() - a;
    const double length = edge.norm();
    // cross(x, y) = ex (y - ay) - ey (x - ax).
    edges.push_back({-edge.y(), edge.x(), edge.y() * a.x() - edge.x() * a.y(),
                     (margin_ + kSlack) * length, -kSlack * length});
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int j = 0; j < rows_; ++j) {
    const double y_lo = y0_ + j * cell_, y_hi = y_lo + cell_;
    // Inside: x_lo >= in_lo and x_hi <= in_hi. Outside: x_hi < out_left,
    // or x_lo > out_right, or the whole row.
    double in_lo = -kInf, in_hi = kInf, out_left = -kInf, out_right = kInf;
    bool row_can_be_inside = true, row_outside = false;
    for (const Edge& e : edges) {
      const double by_min = std::min(e.B * y_lo, e.B * y_hi) + e.C;
      const double by_max = std::max(e.B * y_lo, e.B * y_hi) + e.C;
      if (e.A > 0.0) {
        in_lo = std::max(in_lo, (e.inside_above - by_min) / e.A);
        out_left = std::max(out_left, (e.outside_below - by_max) / e.A);
      } else if (e.A < 0.0) {
        in_hi = std::min(in_hi, (e.inside_above - by_min) / e.A);
        out_right = std::min(out_right, (e.outside_below - by_max) / e.A);
      } else {
        row_can_be_inside = row_can_be_inside && by_min >= e.inside_above;
        row_outside = row_outside || by_max < e.outside_below;
      }
    }
    for (int i = 0; i < cols_; ++i) {
      const double x_lo = x0_ + i * cell_, x_hi = x_lo + cell_;
      Cell& cell = cells_[static_cast<size_t>(j) * cols_ + i];
      if (row_outside || x_hi < out_left || x_lo > out_right) {
        cell = kOutside;
      } else if (row_can_be_inside && x_lo >= in_lo && x_hi <= in_hi) {
        cell = kInside;
      }
    }
  }
}

bool HullLookup::ExactlyInside(const Eigen::Vector2f& q) const {
  return support_internal::InsideHull(hull_, q, margin_);
}

bool HullLookup::Contains(const Eigen::Vector3f& p) const {
  if (hull_.size() < 3 || !p.allFinite()) return false;
  // As SupportPlane::ToPlane computes it.
  const Eigen::Vector2f q(axis_u_.dot(p), axis_v_.dot(p));
  const double fx = (q.x() - x0_) / cell_, fy = (q.y() - y0_) / cell_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx < cols_ && fy < rows_)) {
    return ExactlyInside(q);
  }
  const Cell cell =
      cells_[static_cast<size_t>(fy) * cols_ + static_cast<size_t>(fx)];
  if (cell == kStraddles) return ExactlyInside(q);
  return cell == kInside;
}

}  // namespace fovea
