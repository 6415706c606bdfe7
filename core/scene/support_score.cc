// The candidate surfaces of SearchSupport and their scores
// (support_grid.h): a plane's parts large enough to be a support, and
// what stands on each, how it lies and whether another is above it.

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "core/scene/support_grid.h"

namespace fovea::support_internal {
namespace {

// Surfaces this parallel are compared for "under another".
constexpr float kParallelAngleDeg = 10.0f;

struct Cluster {
  float min_height = std::numeric_limits<float>::infinity();
  float max_height = -std::numeric_limits<float>::infinity();
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(1e9f);
  Eigen::Vector2f hi = Eigen::Vector2f::Constant(-1e9f);
  float area = 0.0f;
};

// Bounding box of a hull, to skip the edge tests for points far outside.
struct Box2 {
  Eigen::Vector2f lo, hi;
  bool Contains(const Eigen::Vector2f& q) const {
    return q.x() >= lo.x() && q.y() >= lo.y() && q.x() <= hi.x() &&
           q.y() <= hi.y();
  }
};
Box2 BoundsOf(const std::vector<Eigen::Vector2f>& hull) {
  Box2 b{Eigen::Vector2f::Constant(1e9f), Eigen::Vector2f::Constant(-1e9f)};
  for (const Eigen::Vector2f& q : hull) {
    b.lo = b.lo.cwiseMin(q);
    b.hi = b.hi.cwiseMax(q);
  }
  return b;
}

// Grid neighbours within this depth of each other are one surface: the
// larger of kJumpMin and kJumpPerSpacing grid spacings (a surface seen at
// 15 degrees steps about four spacings in depth per grid step).
constexpr float kJumpMin = 0.03f;
constexpr float kJumpPerSpacing = 4.0f;
// What stands on a surface is what rises more than this above it, metres.
constexpr float kStandingMinHeight = 0.025f;

// Labels (1, 2, ...) of the 8-connected clusters of `mask` (grid points)
// whose neighbours do not differ in depth by more than a jump; 0 outside
// the mask. Returns the number of labels + 1.
int DepthConnectedClusters(const Grid& grid, const std::vector<uint8_t>& mask,
                           std::vector<int>& labels) {
  const float spacing_per_z =
      static_cast<float>(grid.stride / grid.intrinsics.fx);
  return LabelGridComponents(
      grid, mask,
      [&](int i) {
        const float z = grid.p[i].z();
        const float jump =
            std::max(kJumpMin, kJumpPerSpacing * spacing_per_z * z);
        return [&grid, z, jump](int j, bool /*diagonal*/) {
          return std::abs(grid.p[j].z() - z) <= jump;
        };
      },
      labels);
}

// How many object-sized clusters stand on `c`: clusters (depth-connected)
// of everything above it, of which most lies inside its hull, that reach
// down to it, rise no higher than an object and are no wider than one. A
// table standing on a floor is one cluster with its legs and what stands
// on it: furniture, not an object.
// Also returns, in `weighted`, their sum of exp(-distance / near_scale_m)
// (distance from the camera to each one's centroid).
int CountStandingObjects(const Grid& grid, const Candidate& c,
                         const SupportPlaneOptions& options, float* weighted) {
  *weighted = 0.0f;
  std::vector<uint8_t> above(grid.size(), 0);
  std::vector<float> height(grid.size(), 0.0f);
  for (int i = 0; i < grid.size(); ++i) {
    if (!grid.HasPoint(i)) continue;
    const Eigen::Vector3f& p = grid.p[i];
    const float h = c.plane.Height(p);
    // Twice the band (at least kStandingMinHeight): a surface bent by a
    // centimetre, or the noise along the band's edge, is not a sheet that
    // joins everything on it into one cluster.
    if (!(h > std::max(kStandingMinHeight,
                       2.0f * InlierDistance(p.z(), options)))) {
      continue;
    }
    above[i] = 1;
    height[i] = h;
  }
  std::vector<int> labels;
  const int n = DepthConnectedClusters(grid, above, labels);
  if (n <= 1) return 0;
  struct Stats {
    Cluster shape;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    int points = 0;
    int inside = 0;
  };
  std::vector<Stats> clusters(n);
  const Box2 bounds = BoundsOf(c.frame.hull);
  for (int i = 0; i < grid.size(); ++i) {
    const int l = labels[i];
    if (l == 0) continue;
    Stats& k = clusters[l];
    k.shape.min_height = std::min(k.shape.min_height, height[i]);
    k.shape.max_height = std::max(k.shape.max_height, height[i]);
    const Eigen::Vector2f q = c.frame.ToPlane(grid.p[i]);
    k.shape.lo = k.shape.lo.cwiseMin(q);
    k.shape.hi = k.shape.hi.cwiseMax(q);
    k.shape.area += grid.Area(i, c.plane.normal);
    k.sum += grid.p[i];
    ++k.points;
    k.inside += bounds.Contains(q) && InsideHull(c.frame.hull, q, 0.0f);
  }
  int objects = 0;
  for (int l = 1; l < n; ++l) {
    const Stats& k = clusters[l];
    if (2 * k.inside >= k.points &&
        k.shape.min_height <= options.max_contact_gap &&
        k.shape.max_height <= options.max_object_height &&
        (k.shape.hi - k.shape.lo).norm() <= options.max_object_size &&
        k.shape.area >= options.min_object_area_m2) {
      ++objects;
      *weighted += std::exp(-(k.sum / k.points).norm() / options.near_scale_m);
    }
  }
  return objects;
}

// A hull vertex of `from` (plane coordinates of its frame) in 3D.
Eigen::Vector3f HullPoint(const SupportPlane& from, const Eigen::Vector2f& q) {
  return q.x() * from.axis_u + q.y() * from.axis_v - from.d * from.normal;
}

// Distance in `b`'s plane between the hulls of two candidates (0 when they
// overlap), metres.
float HullDistance(const Candidate& a, const Candidate& b) {
  std::vector<Eigen::Vector2f> pa;
  for (const Eigen::Vector2f& q : a.frame.hull) {
    pa.push_back(b.frame.ToPlane(HullPoint(a.frame, q)));
  }
  const std::vector<Eigen::Vector2f>& pb = b.frame.hull;
  for (const Eigen::Vector2f& q : pa) {
    if (InsideHull(pb, q, 0.0f)) return 0.0f;
  }
  for (const Eigen::Vector2f& q : pb) {
    if (InsideHull(pa, q, 0.0f)) return 0.0f;
  }
  auto point_segment = [](const Eigen::Vector2f& p, const Eigen::Vector2f& s0,
                          const Eigen::Vector2f& s1) {
    const Eigen::Vector2f e = s1 - s0;
    const float t = std::clamp(
        (p - s0).dot(e) / std::max(e.squaredNorm(), 1e-12f), 0.0f, 1.0f);
    return (s0 + t * e - p).norm();
  };
  float best = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < pa.size(); ++i) {
    for (size_t j = 0; j < pb.size(); ++j) {
      best =
          std::min({best, point_segment(pa[i], pb[j], pb[(j + 1) % pb.size()]),
                    point_segment(pb[j], pa[i], pa[(i + 1) % pa.size()])});
    }
  }
  return best;
}

}  // namespace

std::vector<Candidate> SplitIntoSurfaces(const Grid& grid, const Plane& plane,
                                         const SupportPlaneOptions& options,
                                         float min_cos, bool refit) {
  const std::vector<std::vector<int>> parts =
      PlaneParts(grid, plane, options, min_cos, {});
  const int n = static_cast<int>(parts.size());
  std::vector<Candidate> candidates;
  for (int l = 1; l < n; ++l) {
    float area = 0.0f;
    for (const int i : parts[l]) area += grid.Area(i, plane.normal);
    if (area < options.min_candidate_area_m2) continue;
    Candidate c;
    c.plane = plane;
    if (refit) {
      const std::optional<Plane> fit = FitPlane(grid, parts[l]);
      if (fit && fit->normal.dot(plane.normal) >=
                     std::cos(kMaxRefitAngleDeg * kDegToRad)) {
        c.plane = *fit;
      }
    }
    c.indices = parts[l];
    c.area_m2 = area;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int i : c.indices) sum += grid.p[i].cast<double>();
    c.centroid = (sum / static_cast<double>(c.indices.size())).cast<float>();
    c.frame.normal = c.plane.normal;
    c.frame.d = c.plane.d;
    SetAxes(c.frame);
    c.frame.hull = HullOfIndices(grid, c.frame, c.indices);
    if (c.frame.hull.size() < 3) continue;
    candidates.push_back(std::move(c));
  }
  return candidates;
}

void ScoreCandidates(const Grid& grid, const SupportPlaneOptions& options,
                     std::vector<Candidate>& candidates) {
  const float parallel = std::cos(kParallelAngleDeg * kDegToRad);
  for (Candidate& c : candidates) {
    SupportScore& s = c.score;
    float weighted_objects = 0.0f;
    s.objects = CountStandingObjects(grid, c, options, &weighted_objects);
    s.area_m2 = c.area_m2;
    s.distance_m = c.centroid.norm();
    s.under_another = false;
    for (const Candidate& o : candidates) {
      if (&o == &c || o.plane.normal.dot(c.plane.normal) < parallel) continue;
      if (c.plane.Height(o.centroid) > options.under_height &&
          HullDistance(o, c) <= options.under_reach) {
        s.under_another = true;
        break;
      }
    }
    // The view term: how near the optical axis the candidate lies.
    const float off_axis =
        std::acos(std::clamp(c.centroid.z() / c.centroid.norm(), -1.0f, 1.0f)) /
        (options.view_scale_deg * kDegToRad);
    if (s.objects > options.max_counted_objects) {
      weighted_objects *=
          static_cast<float>(options.max_counted_objects) / s.objects;
    }
    s.total =
        options.object_weight * weighted_objects +
        options.view_weight * std::exp(-off_axis * off_axis) +
        options.area_weight *
            std::min(s.area_m2 / options.reference_area_m2, 1.0f) +
        options.near_weight * std::exp(-s.distance_m / options.near_scale_m) -
        (s.under_another ? options.under_weight : 0.0f);
  }
}

void AddLevelTerm(const Eigen::Vector3f& up, const SupportPlaneOptions& options,
                  std::vector<Candidate>& candidates) {
  for (Candidate& c : candidates) {
    const float cos_tilt = std::clamp(c.plane.normal.dot(up), -1.0f, 1.0f);
    c.score.tilt_deg = std::acos(cos_tilt) / kDegToRad;
    c.score.total += options.level_weight * std::max(cos_tilt, 0.0f);
  }
}

}  // namespace fovea::support_internal
