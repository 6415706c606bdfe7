#ifndef FOVEA_CORE_SCENE_HULL_LOOKUP_H_
#define FOVEA_CORE_SCENE_HULL_LOOKUP_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/scene/support_plane.h"

namespace fovea {

// SupportPlane::ProjectsInsideHull(p, margin) for every pixel of a frame,
// with the same answer for every p, bit for bit, at a fraction of the cost:
// a grid over the hull's bounding box (at most kCells x kCells cells) says
// for each cell whether all of it is inside (by margin), all of it is
// outside, or it straddles the boundary; only points in straddling cells,
// or off the grid, are tested edge by edge. A cell counts as inside or
// outside only with kSlack metres to spare, so rounding in the per-point
// test cannot disagree with it.
class HullLookup {
 public:
  // Cells along the longer side of the hull's bounding box.
  static constexpr int kCells = 64;
  // Metres a whole cell must clear an edge by to skip the per-point test.
  static constexpr double kSlack = 1e-4;

  // Copies what it needs: `plane` need not outlive it.
  HullLookup(const SupportPlane& plane, float margin);

  // ProjectsInsideHull(p, margin): false for non-finite p.
  bool Contains(const Eigen::Vector3f& p) const;

 private:
  enum Cell : uint8_t { kOutside = 0, kInside = 1, kStraddles = 2 };
  bool ExactlyInside(const Eigen::Vector2f& q) const;

  Eigen::Vector3f axis_u_, axis_v_;
  std::vector<Eigen::Vector2f> hull_;
  float margin_ = 0.0f;
  // The grid: cell (i, j) covers [x0 + i s, x0 + (i+1) s) x [y0 + j s, ...).
  double x0_ = 0.0, y0_ = 0.0, cell_ = 1.0;
  int cols_ = 0, rows_ = 0;
  std::vector<Cell> cells_;
};

}  // namespace fovea

#endif  // FOVEA_CORE_SCENE_HULL_LOOKUP_H_
