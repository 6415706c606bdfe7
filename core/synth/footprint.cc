#include "core/synth/footprint.h"

#include <Eigen/Core>
#include <cmath>

namespace fovea::synth {
namespace {

using Eigen::Vector2f;

// Height intervals closer than this do not count as overlapping, metres
// (an object resting on another touches it at one height).
constexpr float kZEpsilon = 1e-4f;
// Bisection steps of ContactDistance (halves the bracket each step).
constexpr int kBisectionSteps = 40;
// ContactDistance's bracket beyond the bounding circles, metres.
constexpr float kBracketSlack = 0.01f;

}  // namespace

// Whether the 2D footprints come closer than `margin` (exact for discs,
// conservative for rectangles).
bool Overlap(const Footprint& a, const Footprint& b, float margin) {
  if (a.is_circle && b.is_circle) {
    return (a.centre - b.centre).norm() < a.radius + b.radius + margin;
  }
  if (a.is_circle != b.is_circle) {
    const Footprint& circle = a.is_circle ? a : b;
    const Footprint& rect = a.is_circle ? b : a;
    const Vector2f local = rect.ToLocal(circle.centre);
    const Vector2f clamped = local.cwiseMax(-rect.half).cwiseMin(rect.half);
    return (local - clamped).norm() < circle.radius + margin;
  }
  const Vector2f delta = b.centre - a.centre;
  for (const Vector2f& axis : {a.AxisX(), a.AxisY(), b.AxisX(), b.AxisY()}) {
    if (std::abs(delta.dot(axis)) >=
        a.ProjectedRadius(axis) + b.ProjectedRadius(axis) + margin) {
      return false;  // a separating axis
    }
  }
  return true;
}

// Two solids can only intersect if their height intervals and their
// vertical projections both overlap.
bool Collides(const Footprint& a, const Footprint& b, float margin) {
  const bool z_overlap =
      a.z_min < b.z_max - kZEpsilon && b.z_min < a.z_max - kZEpsilon;
  return z_overlap && Overlap(a, b, margin);
}

// Half sizes of the footprint's axis-aligned bounding box.
Vector2f AabbHalf(const Footprint& f) {
  if (f.is_circle) return Vector2f::Constant(f.radius);
  const float c = std::abs(std::cos(f.yaw));
  const float s = std::abs(std::sin(f.yaw));
  return {c * f.half.x() + s * f.half.y(), s * f.half.x() + c * f.half.y()};
}

// Whether `f` lies within the top face of the box footprint `support`.
bool FitsOnTop(const Footprint& f, const Footprint& support) {
  if (f.is_circle) {
    const Vector2f local = support.ToLocal(f.centre);
    return std::abs(local.x()) <= support.half.x() - f.radius &&
           std::abs(local.y()) <= support.half.y() - f.radius;
  }
  for (const float sx : {-1.0f, 1.0f}) {
    for (const float sy : {-1.0f, 1.0f}) {
      const Vector2f corner =
          f.centre + sx * f.half.x() * f.AxisX() + sy * f.half.y() * f.AxisY();
      const Vector2f local = support.ToLocal(corner);
      if (std::abs(local.x()) > support.half.x() ||
          std::abs(local.y()) > support.half.y()) {
        return false;
      }
    }
  }
  return true;
}

// The smallest distance along unit `dir` from `start` at which the body
// `moving` (footprint centred at `start`) no longer overlaps `fixed`
// (bisection; the set of overlapping offsets is convex).
float ContactDistance(const Footprint& fixed, Footprint moving,
                      const Vector2f& start, const Vector2f& dir) {
  float lo = 0.0f;
  float hi = fixed.BoundingRadius() + moving.BoundingRadius() +
             (fixed.centre - start).norm() + kBracketSlack;
  moving.centre = start;
  if (!Overlap(fixed, moving, 0.0f)) return 0.0f;
  for (int i = 0; i < kBisectionSteps; ++i) {
    const float mid = 0.5f * (lo + hi);
    moving.centre = start + mid * dir;
    (Overlap(fixed, moving, 0.0f) ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace fovea::synth
