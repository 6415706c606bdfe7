#ifndef FOVEA_CORE_SYNTH_FOOTPRINT_H_
#define FOVEA_CORE_SYNTH_FOOTPRINT_H_

#include <Eigen/Core>
#include <cmath>

namespace fovea::synth {

// Vertical projections of resting objects, for placing them without
// interpenetration (random_scene.cc). World frame, metres. Two solids can
// only intersect if both their height intervals and their footprints
// overlap, so disjoint footprints are a conservative no-collision test.

// The vertical projection of an object (a disc or an oriented rectangle)
// and its height interval.
struct Footprint {
  Eigen::Vector2f centre = Eigen::Vector2f::Zero();
  bool is_circle = true;
  float radius = 0.0f;  // circle
  Eigen::Vector2f half =
      Eigen::Vector2f::Zero();  // rectangle half sizes on its axes
  float yaw = 0.0f;             // rectangle x axis angle, radians
  float z_min = 0.0f;
  float z_max = 0.0f;

  Eigen::Vector2f AxisX() const { return {std::cos(yaw), std::sin(yaw)}; }
  Eigen::Vector2f AxisY() const { return {-std::sin(yaw), std::cos(yaw)}; }
  float BoundingRadius() const { return is_circle ? radius : half.norm(); }
  // Half length of the projection onto the unit vector `axis`.
  float ProjectedRadius(const Eigen::Vector2f& axis) const {
    if (is_circle) return radius;
    return half.x() * std::abs(axis.dot(AxisX())) +
           half.y() * std::abs(axis.dot(AxisY()));
  }
  // `p` in the rectangle's frame.
  Eigen::Vector2f ToLocal(const Eigen::Vector2f& p) const {
    const Eigen::Vector2f q = p - centre;
    return {q.dot(AxisX()), q.dot(AxisY())};
  }
};

// Whether the 2D footprints come closer than `margin`, metres >= 0. Exact
// for margin 0 (separating axes); with a margin, rectangles are inflated as
// rectangles, so near corners it may also report footprints slightly more
// than `margin` apart (the safe side).
bool Overlap(const Footprint& a, const Footprint& b, float margin);

// Whether two solids may intersect or come closer than `margin`: their
// height intervals overlap (by more than 0.1 mm) and their footprints
// Overlap. False guarantees they do not interpenetrate.
bool Collides(const Footprint& a, const Footprint& b, float margin);

// Half sizes of the footprint's axis-aligned bounding box.
Eigen::Vector2f AabbHalf(const Footprint& f);

// Whether `f` lies within the top face of the box footprint `support`.
bool FitsOnTop(const Footprint& f, const Footprint& support);

// The distance along unit `dir` from `start` at which `moving` (its centre
// moved to `start`) stops overlapping `fixed`: the contact position, just
// on the free side to float precision (bisection; the overlapping offsets
// form a convex set). 0 if they do not overlap at `start`.
float ContactDistance(const Footprint& fixed, Footprint moving,
                      const Eigen::Vector2f& start, const Eigen::Vector2f& dir);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_FOOTPRINT_H_
