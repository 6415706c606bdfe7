#include "core/frame/hull_lookup.h"

#include <algorithm>
#include <cmath>

#include "core/frame/support_grid.h"

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
  cells_.assign(static_cast<size_t>(cols_) * rows_, kInside);
  // Each edge's cross product (|edge| times the signed distance from its
  // line, positive inside) is linear in the point, so over a cell it is
  // smallest and largest at two of its corners.
  std::vector<uint8_t> outside(cells_.size(), 0);
  for (size_t e = 0; e < hull_.size(); ++e) {
    const Eigen::Vector2d a = hull_[e].cast<double>();
    const Eigen::Vector2d edge =
        hull_[(e + 1) % hull_.size()].cast<double>() - a;
    const double length = edge.norm();
    // cross(x, y) = ex (y - ay) - ey (x - ax) = A x + B y + C.
    const double A = -edge.y(), B = edge.x();
    const double C = edge.y() * a.x() - edge.x() * a.y();
    const double inside_above = (margin_ + kSlack) * length;
    const double outside_below = -kSlack * length;
    for (int j = 0; j < rows_; ++j) {
      const double y_lo = y0_ + j * cell_, y_hi = y_lo + cell_;
      const double by_min = std::min(B * y_lo, B * y_hi);
      const double by_max = std::max(B * y_lo, B * y_hi);
      for (int i = 0; i < cols_; ++i) {
        const double x_lo = x0_ + i * cell_, x_hi = x_lo + cell_;
        const double min = std::min(A * x_lo, A * x_hi) + by_min + C;
        const double max = std::max(A * x_lo, A * x_hi) + by_max + C;
        const size_t k = static_cast<size_t>(j) * cols_ + i;
        if (max < outside_below) outside[k] = 1;
        if (!(min >= inside_above) && cells_[k] == kInside) {
          cells_[k] = kStraddles;
        }
      }
    }
  }
  for (size_t k = 0; k < cells_.size(); ++k) {
    if (outside[k]) cells_[k] = kOutside;
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
