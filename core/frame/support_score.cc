// The grid, candidate surfaces, their scores and the support region of
// SearchSupport (support_grid.h).

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/status/status.h"
#include "core/base/lab.h"
#include "core/frame/support_grid.h"

namespace fovea::support_internal {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// A grid point's area is taken at no more than this grazing angle.
constexpr float kMinCosIncidence = 0.2f;
// A refitted part keeps its plane only if within this of the plane found.
constexpr float kMaxRefitAngleDeg = 10.0f;
// Surfaces this parallel are compared for "under another".
constexpr float kParallelAngleDeg = 10.0f;
// Stride of the full-resolution hull's points, pixels.
constexpr int kHullStride = 4;
// A part of the plane joins the region when this share of its points
// projects inside the region's hull.
constexpr float kInsideShare = 0.5f;
// The seen-through test: samples along the gap every this many metres, at
// most kMaxGapSamples; the gap is seen empty when more than this share of
// the samples that could be judged see beyond the plane.
constexpr float kGapSampleStep = 0.01f;
constexpr int kMaxGapSamples = 60;
constexpr float kSeenThroughShare = 0.1f;
constexpr int kMaxRegionPairPoints = 200;  // subsamples for the nearest pair
constexpr int kMaxPartPairPoints = 60;
// Parts of the plane with fewer grid points are specks, not table.
constexpr int kMinPartPoints = 4;
// Plane parts: neighbours at most this many expected grid steps apart.
constexpr float kPlaneStepFactor = 2.5f;
// Weight of lightness in a part's colour distance from the region.
constexpr float kLightnessWeight = 0.5f;

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
  labels.assign(grid.size(), 0);
  int next = 1;
  std::vector<int> stack;
  const float spacing_per_z =
      static_cast<float>(grid.stride / grid.intrinsics.fx);
  for (int seed = 0; seed < grid.size(); ++seed) {
    if (!mask[seed] || labels[seed] != 0) continue;
    labels[seed] = next;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const int r = i / grid.cols, c = i % grid.cols;
      const float z = grid.p[i].z();
      const float jump =
          std::max(kJumpMin, kJumpPerSpacing * spacing_per_z * z);
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if ((dr == 0 && dc == 0) || rr < 0 || cc < 0 || rr >= grid.rows ||
              cc >= grid.cols) {
            continue;
          }
          const int j = rr * grid.cols + cc;
          if (!mask[j] || labels[j] != 0) continue;
          if (!(std::abs(grid.p[j].z() - z) <= jump)) continue;
          labels[j] = next;
          stack.push_back(j);
        }
      }
    }
    ++next;
  }
  return next;
}

}  // namespace

std::vector<std::vector<int>> PlaneParts(const Grid& grid, const Plane& plane,
                                         const SupportPlaneOptions& options,
                                         float min_cos,
                                         const std::vector<int>& also,
                                         std::vector<int>* labels_out) {
  std::vector<uint8_t> mask(grid.size(), 0);
  for (int i = 0; i < grid.size(); ++i) {
    mask[i] =
        grid.HasPoint(i) && IsNearInlier(grid, i, plane, options, min_cos);
  }
  for (const int i : also) mask[i] = 1;
  // Neighbours on one surface of the plane are about one grid step apart
  // in 3D (the step at their depth, stretched by the plane's slant to the
  // ray); farther apart, something hid the plane between them (a bowl's
  // bottom and the table beyond its rim).
  std::vector<int> labels(grid.size(), 0);
  int n = 1;
  std::vector<int> stack;
  const float step_per_z = static_cast<float>(grid.stride / grid.intrinsics.fx);
  for (int seed = 0; seed < grid.size(); ++seed) {
    if (!mask[seed] || labels[seed] != 0) continue;
    labels[seed] = n;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const Eigen::Vector3f& p = grid.p[i];
      const float incidence =
          std::max(kMinCosIncidence, std::abs(plane.normal.dot(p)) / p.norm());
      const float reach = kPlaneStepFactor * step_per_z * p.z() / incidence;
      const int r = i / grid.cols, c = i % grid.cols;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if ((dr == 0 && dc == 0) || rr < 0 || cc < 0 || rr >= grid.rows ||
              cc >= grid.cols) {
            continue;
          }
          const int j = rr * grid.cols + cc;
          if (!mask[j] || labels[j] != 0) continue;
          const float limit = (dr != 0 && dc != 0) ? reach * 1.4142f : reach;
          if (!((grid.p[j] - p).squaredNorm() <= limit * limit)) continue;
          labels[j] = n;
          stack.push_back(j);
        }
      }
    }
    ++n;
  }
  std::vector<std::vector<int>> parts(n);
  for (int i = 0; i < grid.size(); ++i) {
    if (labels[i] > 0) parts[labels[i]].push_back(i);
  }
  if (labels_out != nullptr) *labels_out = std::move(labels);
  return parts;
}

namespace {

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

// Whether the plane between a and b (points on it) is seen empty: the
// cloud shows, along the rays to points of the segment, something beyond
// the plane (the floor through a gap) rather than something in front of it
// (an object hiding it) or the plane itself.
bool GapSeenEmpty(const OrganizedCloud& cloud, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b,
                  const SupportPlaneOptions& options) {
  const float length = (b - a).norm();
  const int steps =
      std::clamp(static_cast<int>(length / kGapSampleStep), 2, kMaxGapSamples);
  const Intrinsics& k = cloud.intrinsics;
  int beyond = 0, judged = 0;
  for (int s = 1; s < steps; ++s) {
    const Eigen::Vector3f q = a + (b - a) * (static_cast<float>(s) / steps);
    if (!(q.z() > 0.0f)) continue;
    const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
    if (u < 0 || v < 0 || u >= cloud.width() || v >= cloud.height()) continue;
    const float seen = cloud.xyz.at<cv::Vec3f>(v, u)[2];
    if (std::isnan(seen)) continue;  // a hole says nothing
    ++judged;
    const float tolerance = 1.5f * InlierDistance(q.z(), options);
    if (seen > q.z() + tolerance) ++beyond;
  }
  return beyond >= 2 && beyond > kSeenThroughShare * judged;
}

// Every `step`-th element, so that at most about `max` remain.
std::vector<int> Thin(const std::vector<int>& indices, int max) {
  const size_t step = std::max<size_t>(1, indices.size() / max);
  std::vector<int> out;
  for (size_t i = 0; i < indices.size(); i += step) out.push_back(indices[i]);
  return out;
}

// The closest pair between two point sets in plane coordinates (thinned).
std::pair<int, int> NearestPair(const Grid& grid, const SupportPlane& frame,
                                const std::vector<int>& a,
                                const std::vector<int>& b, float* distance) {
  const std::vector<int> ta = Thin(a, kMaxRegionPairPoints);
  const std::vector<int> tb = Thin(b, kMaxPartPairPoints);
  std::pair<int, int> best{ta[0], tb[0]};
  float best_d2 = std::numeric_limits<float>::infinity();
  for (const int i : ta) {
    const Eigen::Vector2f qi = frame.ToPlane(grid.p[i]);
    for (const int j : tb) {
      const float d2 = (frame.ToPlane(grid.p[j]) - qi).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = {i, j};
      }
    }
  }
  *distance = std::sqrt(best_d2);
  return best;
}

// The hull of the grid points `indices` in the frame's plane coordinates,
// from each grid row's leftmost and rightmost point only: the image and
// the plane are related by a homography, which keeps segments segments, so
// a row's other points lie between its two ends (up to the noise across
// the plane).
// Mean CIE Lab colour (L in [0, 100]) of the grid points' pixels.
cv::Vec3f MeanLab(const OrganizedCloud& cloud, const Grid& grid,
                  const std::vector<int>& indices) {
  cv::Vec3d sum(0, 0, 0);
  for (const int i : indices) {
    const cv::Vec3b& c = cloud.color.at<cv::Vec3b>(
        (i / grid.cols) * grid.stride, (i % grid.cols) * grid.stride);
    sum += cv::Vec3d(c[0], c[1], c[2]);
  }
  const double n = std::max<size_t>(1, indices.size());
  cv::Mat rgb(
      1, 1, CV_32FC3,
      cv::Scalar(sum[0] / n / 255.0, sum[1] / n / 255.0, sum[2] / n / 255.0));
  cv::Mat lab;
  RgbToLab(rgb, &lab);
  return lab.at<cv::Vec3f>(0, 0);
}

// Distance of the part's mean colour from `reference` (Lab), lightness
// weighted by kLightnessWeight: shading and shadows change lightness
// across one table far more than its hue.
float ColorDistance(const OrganizedCloud& cloud, const Grid& grid,
                    const cv::Vec3f& reference, const std::vector<int>& part) {
  if (cloud.color.empty() || cloud.color.size() != cloud.xyz.size())
    return 0.0f;
  const cv::Vec3f c = MeanLab(cloud, grid, part);
  const float dl = kLightnessWeight * (c[0] - reference[0]);
  const float da = c[1] - reference[1], db = c[2] - reference[2];
  return std::sqrt(dl * dl + da * da + db * db);
}

std::vector<Eigen::Vector2f> HullOfIndices(const Grid& grid,
                                           const SupportPlane& frame,
                                           const std::vector<int>& indices) {
  std::vector<int> first(grid.rows, -1), last(grid.rows, -1);
  for (const int i : indices) {
    const int r = i / grid.cols;
    if (first[r] < 0 || i < first[r]) first[r] = i;
    if (last[r] < 0 || i > last[r]) last[r] = i;
  }
  std::vector<Eigen::Vector2f> points;
  for (int r = 0; r < grid.rows; ++r) {
    if (first[r] < 0) continue;
    points.push_back(frame.ToPlane(grid.p[first[r]]));
    if (last[r] != first[r]) points.push_back(frame.ToPlane(grid.p[last[r]]));
  }
  return ConvexHull(points);
}

}  // namespace

void OrientTowardsCamera(Eigen::Vector3f& normal, float& d) {
  if (d < 0.0f) {
    normal = -normal;
    d = -d;
  }
}

float Grid::Area(int i, const Eigen::Vector3f& normal) const {
  const Eigen::Vector3f& q = p[i];
  const float z = q.z();
  const float pixel = (z * stride / static_cast<float>(intrinsics.fx)) *
                      (z * stride / static_cast<float>(intrinsics.fy));
  const float incidence = std::abs(normal.dot(q)) / q.norm();
  return pixel / std::max(incidence, kMinCosIncidence);
}

Grid MakeGrid(const OrganizedCloud& cloud, int columns) {
  Grid grid;
  grid.stride = std::max(1, (cloud.width() + columns - 1) / columns);
  grid.cols = (cloud.width() + grid.stride - 1) / grid.stride;
  grid.rows = (cloud.height() + grid.stride - 1) / grid.stride;
  grid.intrinsics = cloud.intrinsics;
  grid.p.resize(grid.size());
  grid.n.resize(grid.size());
  for (int r = 0; r < grid.rows; ++r) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(r * grid.stride);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(r * grid.stride);
    for (int c = 0; c < grid.cols; ++c) {
      const int u = c * grid.stride;
      const int i = r * grid.cols + c;
      grid.p[i] = {p[u][0], p[u][1], p[u][2]};
      grid.n[i] = {n[u][0], n[u][1], n[u][2]};
    }
  }
  return grid;
}

std::optional<Plane> FitPlane(const Grid& grid,
                              const std::vector<int>& indices) {
  if (indices.size() < 3) return std::nullopt;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d q = grid.p[i].cast<double>();
    sum += q;
    outer += q * q.transpose();
  }
  const double n = static_cast<double>(indices.size());
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Plane plane;
  plane.normal = eig.eigenvectors().col(0).cast<float>().normalized();
  plane.d = -plane.normal.dot(mean.cast<float>());
  OrientTowardsCamera(plane.normal, plane.d);
  if (!plane.normal.allFinite() || !std::isfinite(plane.d)) return std::nullopt;
  return plane;
}

void SetAxes(SupportPlane& plane) {
  // u along the camera x projected into the plane.
  Eigen::Vector3f u =
      Eigen::Vector3f::UnitX() - plane.normal * plane.normal.x();
  if (u.norm() < 1e-3f) {
    u = Eigen::Vector3f::UnitZ() - plane.normal * plane.normal.z();
  }
  plane.axis_u = u.normalized();
  plane.axis_v = plane.normal.cross(plane.axis_u);
}

bool InsideHull(const std::vector<Eigen::Vector2f>& hull,
                const Eigen::Vector2f& q, float margin) {
  if (hull.size() < 3) return false;
  const float margin2 = margin * margin;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f edge = hull[(i + 1) % hull.size()] - a;
    // cross = |edge| times the signed distance of q from the edge's line,
    // positive inside (the hull is counter-clockwise). Inside by `margin`:
    // cross >= margin |edge|, compared squared to avoid a square root.
    const float cross = edge.x() * (q.y() - a.y()) - edge.y() * (q.x() - a.x());
    if (!(cross >= 0.0f)) return false;  // NaN is outside too
    if (margin > 0.0f && cross * cross < margin2 * edge.squaredNorm()) {
      return false;
    }
  }
  return true;
}

std::vector<Eigen::Vector2f> ConvexHull(
    const std::vector<Eigen::Vector2f>& points) {
  std::vector<Eigen::Vector2f> hull;
  if (points.size() < 3) return hull;
  std::vector<cv::Point2f> pts;
  pts.reserve(points.size());
  for (const Eigen::Vector2f& q : points) pts.emplace_back(q.x(), q.y());
  std::vector<cv::Point2f> h;
  cv::convexHull(pts, h, /*clockwise=*/false);
  hull.reserve(h.size());
  for (const cv::Point2f& q : h) hull.emplace_back(q.x, q.y);
  // Make sure the order is counter-clockwise (positive signed area).
  double area = 0.0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f& b = hull[(i + 1) % hull.size()];
    area +=
        static_cast<double>(a.x()) * b.y() - static_cast<double>(b.x()) * a.y();
  }
  if (area < 0.0) std::reverse(hull.begin(), hull.end());
  if (hull.size() < 3 || std::abs(area) < 1e-9) hull.clear();
  return hull;
}

std::vector<Eigen::Vector2f> HullOfMask(const OrganizedCloud& cloud,
                                        const cv::Mat& mask,
                                        const SupportPlane& plane) {
  std::vector<Eigen::Vector2f> points;
  for (int v = 0; v < cloud.height(); v += kHullStride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const uint8_t* m = mask.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); u += kHullStride) {
      if (!m[u] || std::isnan(p[u][2])) continue;
      points.push_back(plane.ToPlane({p[u][0], p[u][1], p[u][2]}));
    }
  }
  return ConvexHull(points);
}

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

void ScoreCandidates(const Grid& grid, const Eigen::Vector3f& up,
                     const SupportPlaneOptions& options,
                     std::vector<Candidate>& candidates) {
  const float parallel = std::cos(kParallelAngleDeg * kDegToRad);
  for (Candidate& c : candidates) {
    SupportScore& s = c.score;
    float weighted_objects = 0.0f;
    s.objects = CountStandingObjects(grid, c, options, &weighted_objects);
    s.area_m2 = c.area_m2;
    s.distance_m = c.centroid.norm();
    const float cos_tilt = std::clamp(c.plane.normal.dot(up), -1.0f, 1.0f);
    s.tilt_deg = std::acos(cos_tilt) / kDegToRad;
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
        options.near_weight * std::exp(-s.distance_m / options.near_scale_m) +
        options.level_weight * std::max(cos_tilt, 0.0f) -
        (s.under_another ? options.under_weight : 0.0f);
  }
}

absl::StatusOr<SupportPlane> MakeSupportRegion(
    const OrganizedCloud& cloud, const Grid& grid, const Candidate& chosen,
    const SupportPlaneOptions& options, float min_cos) {
  // Every part of the chosen plane, the chosen one among them.
  std::vector<int> labels;
  const std::vector<std::vector<int>> parts =
      PlaneParts(grid, chosen.plane, options, min_cos, chosen.indices, &labels);
  const int n = static_cast<int>(parts.size());
  const int own = labels[chosen.indices[0]];
  std::vector<bool> joined(n, false);
  joined[own] = true;
  std::vector<int> region = parts[own];
  SupportPlane frame = chosen.frame;
  const cv::Vec3f region_color = MeanLab(cloud, grid, region);
  // Two passes: a part that joins widens the hull for the next.
  for (int pass = 0; pass < 2; ++pass) {
    frame.hull = HullOfIndices(grid, frame, region);
    bool grew = false;
    for (int l = 1; l < n; ++l) {
      if (joined[l] || static_cast<int>(parts[l].size()) < kMinPartPoints) {
        continue;
      }
      // Smaller parts are the insides of what stands on the table (a
      // bowl's bottom) as often as the table between objects; left out, the
      // segmentation treats both as what they touch.
      float area = 0.0f;
      for (const int i : parts[l]) area += grid.Area(i, chosen.plane.normal);
      if (area < options.min_candidate_area_m2) continue;
      int inside = 0;
      for (const int i : parts[l]) {
        inside += InsideHull(frame.hull, frame.ToPlane(grid.p[i]), 0.0f);
      }
      // A part of another colour than the region is the inside of
      // something standing on it (a bowl's bottom), not the table.
      if (ColorDistance(cloud, grid, region_color, parts[l]) >
          options.max_join_color_distance) {
        continue;
      }
      bool join = inside >= kInsideShare * parts[l].size();
      if (!join) {
        float gap = 0.0f;
        const auto [a, b] = NearestPair(grid, frame, region, parts[l], &gap);
        if (gap <= options.max_occlusion_gap) {
          // The two ends, dropped onto the plane.
          const Eigen::Vector3f pa =
              grid.p[a] - chosen.plane.normal * chosen.plane.Height(grid.p[a]);
          const Eigen::Vector3f pb =
              grid.p[b] - chosen.plane.normal * chosen.plane.Height(grid.p[b]);
          join = !GapSeenEmpty(cloud, pa, pb, options);
        }
      }
      if (join) {
        joined[l] = true;
        region.insert(region.end(), parts[l].begin(), parts[l].end());
        grew = true;
      }
    }
    if (!grew) break;
  }

  SupportPlane plane;
  const std::optional<Plane> fit = FitPlane(grid, region);
  const Plane best = fit && fit->normal.dot(chosen.plane.normal) >=
                                 std::cos(kMaxRefitAngleDeg * kDegToRad)
                         ? *fit
                         : chosen.plane;
  plane.normal = best.normal;
  plane.d = best.d;
  SetAxes(plane);

  // Full resolution: pixels on the plane whose grid cell (or a neighbour of
  // it) belongs to the region.
  cv::Mat member(grid.rows, grid.cols, CV_8UC1, cv::Scalar(0));
  for (const int i : region)
    member.at<uint8_t>(i / grid.cols, i % grid.cols) = 255;
  // Cells of no point (holes, edges) take their neighbours' membership;
  // cells of another surface do not.
  cv::Mat grown;
  cv::dilate(member, grown, cv::Mat());
  for (int i = 0; i < grid.size(); ++i) {
    if (!grid.HasPoint(i)) {
      member.at<uint8_t>(i / grid.cols, i % grid.cols) =
          grown.at<uint8_t>(i / grid.cols, i % grid.cols);
    }
  }
  const float min_cos_full = min_cos;
  plane.inliers =
      cv::Mat(cloud.height(), cloud.width(), CV_8UC1, cv::Scalar(0));
  int count = 0;
  // Only the pixels of the member cells' bounding box can be inliers.
  const cv::Rect cells = cv::boundingRect(member);
  const int u_begin = std::max(0, cells.x * grid.stride - grid.stride);
  const int u_end = std::min(
      cloud.width(), (cells.x + cells.width) * grid.stride + grid.stride);
  const int v_begin = std::max(0, cells.y * grid.stride - grid.stride);
  const int v_end = std::min(
      cloud.height(), (cells.y + cells.height) * grid.stride + grid.stride);
  for (int v = v_begin; v < v_end; ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* nrm = cloud.normals.ptr<cv::Vec3f>(v);
    const uint8_t* m = member.ptr<uint8_t>(
        std::min(grid.rows - 1, (v + grid.stride / 2) / grid.stride));
    uint8_t* out = plane.inliers.ptr<uint8_t>(v);
    for (int u = u_begin; u < u_end; ++u) {
      if (std::isnan(p[u][2])) continue;
      if (!m[std::min(grid.cols - 1, (u + grid.stride / 2) / grid.stride)]) {
        continue;
      }
      const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
      if (!(std::abs(best.Height(q)) <= InlierDistance(q.z(), options))) {
        continue;
      }
      if (!std::isnan(nrm[u][2]) &&
          std::abs(best.normal.dot(Eigen::Vector3f(
              nrm[u][0], nrm[u][1], nrm[u][2]))) < min_cos_full) {
        continue;
      }
      out[u] = 255;
      ++count;
    }
  }
  plane.inlier_count = count;
  plane.hull = HullOfMask(cloud, plane.inliers, plane);
  if (plane.hull.size() < 3) {
    return absl::NotFoundError("support plane: the region has no 2D extent");
  }
  return plane;
}

}  // namespace fovea::support_internal
