#include "core/synth/raycast.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/base/check.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using Eigen::Vector3f;

constexpr float kInf = std::numeric_limits<float>::infinity();
// Below this, a direction component or quadratic coefficient counts as zero.
constexpr float kTiny = 1e-12f;
// Hits closer than this to the ray origin are ignored (camera z, metres).
constexpr float kMinDepth = 1e-4f;
// Slack on the bounds of curved patches (cone apex, cylinder rims), metres,
// so that rays through an apex or rim are not lost to rounding.
constexpr float kBoundSlack = 1e-6f;

// Real roots of a t^2 + 2 b t + c = 0, ascending; numerically stable form.
// Returns the number of roots (0, 1 or 2).
int SolveQuadratic(float a, float b, float c, float roots[2]) {
  if (std::abs(a) < kTiny) {
    if (std::abs(b) < kTiny) return 0;
    roots[0] = -c / (2.0f * b);
    return 1;
  }
  const float disc = b * b - a * c;
  if (disc < 0.0f) return 0;
  const float q = -(b + std::copysign(std::sqrt(disc), b));
  if (std::abs(q) < kTiny) {  // b = 0 and disc = 0: double root at 0
    roots[0] = 0.0f;
    return 1;
  }
  roots[0] = q / a;
  roots[1] = c / q;
  if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  return 2;
}

// Keeps the hit (t, normal) in `best` if t is in (t_min, t_max) and nearer
// than `best`.
void KeepNearest(float t, const Vector3f& normal, float t_min, float t_max,
                 std::optional<RayHit>* best) {
  if (t <= t_min || t >= t_max) return;
  if (best->has_value() && t >= (*best)->t) return;
  *best = RayHit{t, normal};
}

// The local-frame intersections below: o, d in the primitive's local frame.

std::optional<RayHit> IntersectBox(const Vector3f& h, const Vector3f& o,
                                   const Vector3f& d, float t_min,
                                   float t_max) {
  float t_near = -kInf;
  float t_far = kInf;
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < kTiny) {
      if (std::abs(o[i]) > h[i]) return std::nullopt;
      continue;
    }
    const float inv = 1.0f / d[i];
    float ta = (-h[i] - o[i]) * inv;
    float tb = (h[i] - o[i]) * inv;
    if (ta > tb) std::swap(ta, tb);
    if (ta > t_near) {
      t_near = ta;
      axis = i;
    }
    t_far = std::min(t_far, tb);
    if (t_near > t_far) return std::nullopt;
  }
  // The ray starts inside the box (t_near <= t_min) only if the camera is in
  // a box; that is not a visible surface.
  if (axis < 0 || t_near <= t_min || t_near >= t_max) return std::nullopt;
  Vector3f normal = Vector3f::Zero();
  normal[axis] = d[axis] > 0.0f ? -1.0f : 1.0f;
  return RayHit{t_near, normal};
}

std::optional<RayHit> IntersectSphere(float r, const Vector3f& o,
                                      const Vector3f& d, float t_min,
                                      float t_max) {
  float roots[2];
  const int n =
      SolveQuadratic(d.squaredNorm(), o.dot(d), o.squaredNorm() - r * r, roots);
  std::optional<RayHit> best;
  for (int i = 0; i < n; ++i) {
    KeepNearest(roots[i], ((o + roots[i] * d) / r).normalized(), t_min, t_max,
                &best);
  }
  return best;
}

std::optional<RayHit> IntersectCylinder(float r, float h, const Vector3f& o,
                                        const Vector3f& d, float t_min,
                                        float t_max) {
  std::optional<RayHit> best;
  float roots[2];
  const int n = SolveQuadratic(d.x() * d.x() + d.y() * d.y(),
                               o.x() * d.x() + o.y() * d.y(),
                               o.x() * o.x() + o.y() * o.y() - r * r, roots);
  for (int i = 0; i < n; ++i) {
    const Vector3f p = o + roots[i] * d;
    if (std::abs(p.z()) <= h + kBoundSlack) {
      KeepNearest(roots[i], Vector3f(p.x(), p.y(), 0.0f).normalized(), t_min,
                  t_max, &best);
    }
  }
  if (std::abs(d.z()) >= kTiny) {
    for (const float cap : {-h, h}) {
      const float t = (cap - o.z()) / d.z();
      const Vector3f p = o + t * d;
      if (p.x() * p.x() + p.y() * p.y() <= r * r + kBoundSlack) {
        KeepNearest(t, Vector3f(0.0f, 0.0f, cap > 0.0f ? 1.0f : -1.0f), t_min,
                    t_max, &best);
      }
    }
  }
  return best;
}

// Cone: base disc of radius r at z = -h, apex at z = +h. Its side is
// x^2 + y^2 = k^2 (h - z)^2 with k = r / (2h) and 0 <= h - z <= 2h.
std::optional<RayHit> IntersectCone(float r, float h, const Vector3f& o,
                                    const Vector3f& d, float t_min,
                                    float t_max) {
  std::optional<RayHit> best;
  const float k2 = (r / (2.0f * h)) * (r / (2.0f * h));
  const float w0 = h - o.z();  // h - z at t = 0; h - z(t) = w0 - t d.z
  float roots[2];
  const int n =
      SolveQuadratic(d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z(),
                     o.x() * d.x() + o.y() * d.y() + k2 * w0 * d.z(),
                     o.x() * o.x() + o.y() * o.y() - k2 * w0 * w0, roots);
  for (int i = 0; i < n; ++i) {
    const Vector3f p = o + roots[i] * d;
    const float w = h - p.z();
    if (w >= -kBoundSlack && w <= 2.0f * h + kBoundSlack) {
      KeepNearest(roots[i], Vector3f(p.x(), p.y(), k2 * w).normalized(), t_min,
                  t_max, &best);
    }
  }
  if (std::abs(d.z()) >= kTiny) {
    const float t = (-h - o.z()) / d.z();
    const Vector3f p = o + t * d;
    if (p.x() * p.x() + p.y() * p.y() <= r * r + kBoundSlack) {
      KeepNearest(t, -Vector3f::UnitZ(), t_min, t_max, &best);
    }
  }
  return best;
}

// The hits of the sphere |p - c| = r whose point satisfies `keep`, with
// normal (p - c) / r times `sign` (+1 outward, -1 inward).
template <typename Keep>
void SphereHits(const Vector3f& c, float r, float sign, const Vector3f& o,
                const Vector3f& d, float t_min, float t_max, Keep keep,
                std::optional<RayHit>* best) {
  const Vector3f oc = o - c;
  float roots[2];
  const int n = SolveQuadratic(d.squaredNorm(), oc.dot(d),
                               oc.squaredNorm() - r * r, roots);
  for (int i = 0; i < n; ++i) {
    const Vector3f p = o + roots[i] * d;
    if (keep(p)) KeepNearest(roots[i], sign * (p - c) / r, t_min, t_max, best);
  }
}

// The hits of the vertical cylinder x^2 + y^2 = r^2 with z in [z0, z1].
void CylinderSideHits(float r, float z0, float z1, float sign,
                      const Vector3f& o, const Vector3f& d, float t_min,
                      float t_max, std::optional<RayHit>* best) {
  float roots[2];
  const int n = SolveQuadratic(d.x() * d.x() + d.y() * d.y(),
                               o.x() * d.x() + o.y() * d.y(),
                               o.x() * o.x() + o.y() * o.y() - r * r, roots);
  for (int i = 0; i < n; ++i) {
    const Vector3f p = o + roots[i] * d;
    if (p.z() >= z0 - kBoundSlack && p.z() <= z1 + kBoundSlack) {
      KeepNearest(roots[i], sign * Vector3f(p.x(), p.y(), 0.0f).normalized(),
                  t_min, t_max, best);
    }
  }
}

// The hit of the horizontal annulus at height z with radii in
// [r_in, r_out], normal +z times `sign`.
void AnnulusHit(float z, float r_in, float r_out, float sign, const Vector3f& o,
                const Vector3f& d, float t_min, float t_max,
                std::optional<RayHit>* best) {
  if (std::abs(d.z()) < kTiny || !(r_out > 0.0f)) return;
  const float t = (z - o.z()) / d.z();
  const Vector3f p = o + t * d;
  const float rho2 = p.x() * p.x() + p.y() * p.y();
  if (rho2 >= r_in * r_in - kBoundSlack &&
      rho2 <= r_out * r_out + kBoundSlack) {
    KeepNearest(t, Vector3f(0.0f, 0.0f, sign), t_min, t_max, best);
  }
}

// Bowl: see synth_scene.h. Outer sphere centre (0, 0, h), radius r, cut at
// the foot z = -h. The inside is the sphere through the rim's inner circle
// (radius r - w at z = h) whose lowest point is the floor,
// z_floor = -h + max(w, floor): with depth D = h - z_floor its radius is
// ((r - w)^2 + D^2) / (2 D), so the inside curves smoothly down to the
// floor as a real bowl's does. With a flat floor of radius rf > 0 the
// inside is the sphere through the rim's inner circle and the floor's edge
// (centre on the axis at z_c, from r_rim^2 + (h - z_c)^2 =
// rf^2 + (z_floor - z_c)^2), cut at the floor, plus the floor disc.
std::optional<RayHit> IntersectBowl(float r, float h, float w, float floor,
                                    float rf, const Vector3f& o,
                                    const Vector3f& d, float t_min,
                                    float t_max) {
  std::optional<RayHit> best;
  const float r_rim = r - w;
  const float z_foot = -h;
  const float z_floor = -h + std::max(w, floor);
  const float depth = h - z_floor;
  SphereHits(
      Vector3f(0.0f, 0.0f, h), r, 1.0f, o, d, t_min, t_max,
      [&](const Vector3f& p) {
        return p.z() <= h + kBoundSlack && p.z() >= z_foot - kBoundSlack;
      },
      &best);
  if (rf > 0.0f) {
    const float z_c =
        (r_rim * r_rim + h * h - rf * rf - z_floor * z_floor) / (2.0f * depth);
    const float r_in = std::sqrt(rf * rf + (z_floor - z_c) * (z_floor - z_c));
    SphereHits(
        Vector3f(0.0f, 0.0f, z_c), r_in, -1.0f, o, d, t_min, t_max,
        [&](const Vector3f& p) {
          return p.z() <= h + kBoundSlack && p.z() >= z_floor - kBoundSlack;
        },
        &best);
    AnnulusHit(z_floor, 0.0f, rf, 1.0f, o, d, t_min, t_max, &best);
  } else {
    const float r_in = (r_rim * r_rim + depth * depth) / (2.0f * depth);
    SphereHits(
        Vector3f(0.0f, 0.0f, z_floor + r_in), r_in, -1.0f, o, d, t_min, t_max,
        [&](const Vector3f& p) { return p.z() <= h + kBoundSlack; }, &best);
  }
  AnnulusHit(h, r_rim, r, 1.0f, o, d, t_min, t_max, &best);  // the rim
  const float foot =
      std::sqrt(std::max(0.0f, r * r - (h - z_foot) * (h - z_foot)));
  AnnulusHit(z_foot, 0.0f, foot, -1.0f, o, d, t_min, t_max, &best);
  return best;
}

// Cup: outer radius r, wall and bottom w thick, z in [-h, h], open top.
std::optional<RayHit> IntersectCup(float r, float h, float w, const Vector3f& o,
                                   const Vector3f& d, float t_min,
                                   float t_max) {
  std::optional<RayHit> best;
  const float r_in = r - w;
  CylinderSideHits(r, -h, h, 1.0f, o, d, t_min, t_max, &best);
  CylinderSideHits(r_in, -h + w, h, -1.0f, o, d, t_min, t_max, &best);
  AnnulusHit(h, r_in, r, 1.0f, o, d, t_min, t_max, &best);          // rim
  AnnulusHit(-h, 0.0f, r, -1.0f, o, d, t_min, t_max, &best);        // foot
  AnnulusHit(-h + w, 0.0f, r_in, 1.0f, o, d, t_min, t_max, &best);  // inside
  return best;
}

std::optional<RayHit> IntersectLocal(const Primitive& primitive,
                                     const Vector3f& o, const Vector3f& d,
                                     float t_min, float t_max) {
  const Vector3f& h = primitive.half_extents;
  switch (primitive.shape) {
    case Shape::kBox:
      return IntersectBox(h, o, d, t_min, t_max);
    case Shape::kCylinder:
      return IntersectCylinder(primitive.radius, h.z(), o, d, t_min, t_max);
    case Shape::kSphere:
      return IntersectSphere(primitive.radius, o, d, t_min, t_max);
    case Shape::kCone:
      return IntersectCone(primitive.radius, h.z(), o, d, t_min, t_max);
    case Shape::kBowl:
      return IntersectBowl(primitive.radius, h.z(), primitive.thickness,
                           primitive.floor_height, primitive.floor_radius, o, d,
                           t_min, t_max);
    case Shape::kCup:
      return IntersectCup(primitive.radius, h.z(), primitive.thickness, o, d,
                          t_min, t_max);
  }
  return std::nullopt;
}

// The radius of a sphere about the local origin enclosing the primitive.
float BoundingRadius(const Primitive& primitive) {
  const Vector3f& h = primitive.half_extents;
  const float r = primitive.radius;
  switch (primitive.shape) {
    case Shape::kBox:
      return h.norm();
    case Shape::kCylinder:
    case Shape::kCone:
    case Shape::kCup:
      return std::sqrt(r * r + h.z() * h.z());
    case Shape::kSphere:
      return r;
    case Shape::kBowl:
      return std::sqrt(r * r + h.z() * h.z());  // rim circle at z = +h
  }
  return h.norm() + r;
}

// A primitive with what every ray needs precomputed, for RaycastScene.
struct PreparedPrimitive {
  const Primitive* primitive;  // not owned; points into the SceneSpec
  Eigen::Matrix3f world_to_local;
  Vector3f origin_local;  // the camera centre in the local frame
  Vector3f origin_rel;    // camera centre minus the bounding sphere centre
  float bound_c;          // |origin_rel|^2 - bounding radius^2
};

// Whether the ray can hit the bounding sphere at some t in (kMinDepth, t_max).
bool MayHit(const PreparedPrimitive& p, const Vector3f& d, float t_max) {
  const float a = d.squaredNorm();
  const float b = p.origin_rel.dot(d);
  const float disc = b * b - a * p.bound_c;
  if (disc < 0.0f) return false;
  const float s = std::sqrt(disc);
  return (-b + s) > kMinDepth * a && (-b - s) < t_max * a;
}

}  // namespace

std::optional<RayHit> IntersectPrimitive(const Primitive& primitive,
                                         const Vector3f& origin,
                                         const Vector3f& direction, float t_min,
                                         float t_max) {
  const Eigen::Matrix3f world_to_local = primitive.pose.linear().transpose();
  std::optional<RayHit> hit = IntersectLocal(
      primitive, world_to_local * (origin - primitive.pose.translation()),
      world_to_local * direction, t_min, t_max);
  if (hit.has_value()) hit->normal = primitive.pose.linear() * hit->normal;
  return hit;
}

std::optional<RayHit> IntersectTable(const Eigen::Vector2f& table_half_size,
                                     const Vector3f& origin,
                                     const Vector3f& direction, float t_min,
                                     float t_max) {
  if (std::abs(direction.z()) < kTiny) return std::nullopt;
  const float t = -origin.z() / direction.z();
  if (t <= t_min || t >= t_max) return std::nullopt;
  const Vector3f p = origin + t * direction;
  if (std::abs(p.x()) > table_half_size.x() ||
      std::abs(p.y()) > table_half_size.y()) {
    return std::nullopt;
  }
  return RayHit{t, Vector3f::UnitZ()};
}

RaycastImage RaycastScene(const SceneSpec& spec) {
  FOVEA_CHECK(spec.width > 0 && spec.height > 0);
  FOVEA_CHECK(spec.intrinsics.fx > 0.0 && spec.intrinsics.fy > 0.0);
  const Eigen::Matrix3f cam_to_world = spec.camera_pose.linear();
  const Vector3f eye = spec.camera_pose.translation();

  // Objects first, then the background parts, then the object parts: hit
  // index k + 1 is prepared[k].
  std::vector<const Primitive*> primitives;
  primitives.reserve(spec.objects.size() + spec.background.size() +
                     spec.object_parts.size());
  for (const Primitive& primitive : spec.objects)
    primitives.push_back(&primitive);
  for (const BackgroundPart& part : spec.background) {
    primitives.push_back(&part.primitive);
  }
  for (const ObjectPart& part : spec.object_parts) {
    primitives.push_back(&part.primitive);
  }
  std::vector<PreparedPrimitive> prepared;
  prepared.reserve(primitives.size());
  for (const Primitive* primitive_ptr : primitives) {
    const Primitive& primitive = *primitive_ptr;
    PreparedPrimitive p;
    p.primitive = &primitive;
    p.world_to_local = primitive.pose.linear().transpose();
    p.origin_local = p.world_to_local * (eye - primitive.pose.translation());
    p.origin_rel = eye - primitive.pose.translation();
    const float bound = BoundingRadius(primitive) * 1.001f + 1e-4f;
    p.bound_c = p.origin_rel.squaredNorm() - bound * bound;
    prepared.push_back(p);
  }

  RaycastImage out;
  out.depth.create(spec.height, spec.width, CV_32FC1);
  out.hit.create(spec.height, spec.width, CV_32SC1);
  out.normal.create(spec.height, spec.width, CV_32FC3);
  const float fx = static_cast<float>(spec.intrinsics.fx);
  const float fy = static_cast<float>(spec.intrinsics.fy);
  const float cx = static_cast<float>(spec.intrinsics.cx);
  const float cy = static_cast<float>(spec.intrinsics.cy);
  const float nan = std::numeric_limits<float>::quiet_NaN();

  for (int v = 0; v < spec.height; ++v) {
    float* depth_row = out.depth.ptr<float>(v);
    int* hit_row = out.hit.ptr<int>(v);
    cv::Vec3f* normal_row = out.normal.ptr<cv::Vec3f>(v);
    const Vector3f row_dir =
        cam_to_world * Vector3f(0.0f, (static_cast<float>(v) - cy) / fy, 1.0f);
    for (int u = 0; u < spec.width; ++u) {
      // Camera-frame direction (x, y, 1): t is the camera depth z.
      const Vector3f d =
          row_dir + cam_to_world.col(0) * ((static_cast<float>(u) - cx) / fx);
      int best_index = -1;
      std::optional<RayHit> best =
          IntersectTable(spec.table_half_size, eye, d, kMinDepth, kInf);
      if (best.has_value()) best_index = 0;
      for (size_t k = 0; k < prepared.size(); ++k) {
        const PreparedPrimitive& p = prepared[k];
        const float t_max = best.has_value() ? best->t : kInf;
        if (!MayHit(p, d, t_max)) continue;
        std::optional<RayHit> hit =
            IntersectLocal(*p.primitive, p.origin_local, p.world_to_local * d,
                           kMinDepth, t_max);
        if (hit.has_value()) {
          hit->normal = p.primitive->pose.linear() * hit->normal;
          best = hit;
          best_index = static_cast<int>(k) + 1;
        }
      }
      if (!best.has_value()) {
        depth_row[u] = nan;
        hit_row[u] = -1;
        normal_row[u] = cv::Vec3f(0.0f, 0.0f, 0.0f);
        continue;
      }
      Vector3f n = best->normal;
      if (n.dot(d) > 0.0f) n = -n;  // seen from behind (under the table)
      depth_row[u] = best->t;
      hit_row[u] = best_index;
      normal_row[u] = cv::Vec3f(n.x(), n.y(), n.z());
    }
  }
  return out;
}

std::vector<int> ReducedObjectPixelCounts(SceneSpec spec, int max_width) {
  const double scale =
      std::min(0.5, static_cast<double>(max_width) / spec.width);
  spec.width = std::max(1, static_cast<int>(spec.width * scale));
  spec.height = std::max(1, static_cast<int>(spec.height * scale));
  spec.background.clear();
  Intrinsics& k = spec.intrinsics;
  k.fx *= scale;
  k.fy *= scale;
  k.cx = (k.cx + 0.5) * scale - 0.5;
  k.cy = (k.cy + 0.5) * scale - 0.5;
  std::vector<int> object_of_hit = {-1};
  for (size_t i = 0; i < spec.objects.size(); ++i) {
    object_of_hit.push_back(static_cast<int>(i));
  }
  for (const ObjectPart& part : spec.object_parts) {
    object_of_hit.push_back(part.object);
  }
  const RaycastImage ray = RaycastScene(spec);
  std::vector<int> counts(spec.objects.size(), 0);
  for (int v = 0; v < ray.hit.rows; ++v) {
    const int* row = ray.hit.ptr<int>(v);
    for (int u = 0; u < ray.hit.cols; ++u) {
      if (row[u] > 0 && object_of_hit[row[u]] >= 0) {
        ++counts[object_of_hit[row[u]]];
      }
    }
  }
  return counts;
}

}  // namespace fovea::synth
