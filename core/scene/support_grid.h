#ifndef FOVEA_CORE_SCENE_SUPPORT_GRID_H_
#define FOVEA_CORE_SCENE_SUPPORT_GRID_H_

// The pieces SearchSupport (support_plane.cc) is made of: a subsampled
// grid of the cloud and its geometry (support_grid.cc), planes' connected
// parts as candidate surfaces and their scores (support_score.cc), and the
// chosen one's support region (support_region.cc). Internal to
// core/frame; tests reach the behaviour through SearchSupport.

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"

namespace fovea::support_internal {

inline constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// A refitted part keeps its plane only if within this of the plane found.
inline constexpr float kMaxRefitAngleDeg = 10.0f;

struct Plane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit, to the camera
  float d = 0.0f;
  float Height(const Eigen::Vector3f& p) const { return normal.dot(p) + d; }
};

// Every stride-th row and column of a cloud; NaN where there is no point
// or normal.
struct Grid {
  int stride = 1;
  int cols = 0;
  int rows = 0;
  Intrinsics intrinsics;  // of the full-resolution cloud
  std::vector<Eigen::Vector3f> p;
  std::vector<Eigen::Vector3f> n;

  int size() const { return cols * rows; }
  bool HasPoint(int i) const { return !std::isnan(p[i].z()); }
  bool HasNormal(int i) const { return !std::isnan(n[i].z()); }
  // Visible area a grid point stands for, m^2: its stride x stride pixels
  // at its depth, seen at its angle to `normal` (clamped at 78 degrees).
  float Area(int i, const Eigen::Vector3f& normal) const;
};

// Orients a plane towards the camera (origin): n . 0 + d > 0.
void OrientTowardsCamera(Eigen::Vector3f& normal, float& d);

// The grid of at most `columns` columns.
Grid MakeGrid(const OrganizedCloud& cloud, int columns);

// max(inlier_distance, inlier_sigmas * sigma(z)), metres.
inline float InlierDistance(float z, const SupportPlaneOptions& options) {
  const float band =
      options.inlier_sigmas * (options.sigma0_m + options.sigma_per_z2 * z * z);
  return band > options.inlier_distance ? band : options.inlier_distance;
}
// Within InlierDistance of `plane` with a normal within the angle
// (cos >= min_cos) of it. (Inline: RANSAC calls it a million times a
// frame.)
inline bool IsInlier(const Grid& grid, int i, const Plane& plane,
                     const SupportPlaneOptions& options, float min_cos) {
  const Eigen::Vector3f& p = grid.p[i];
  const float h = plane.Height(p);
  const float band = InlierDistance(p.z(), options);
  if (!(h <= band && h >= -band)) return false;
  const float c = plane.normal.dot(grid.n[i]);
  return c >= min_cos || c <= -min_cos;  // NaN: false
}
// The same, but points without a normal (edges, noise) count when close.
inline bool IsNearInlier(const Grid& grid, int i, const Plane& plane,
                         const SupportPlaneOptions& options, float min_cos) {
  const Eigen::Vector3f& p = grid.p[i];
  const float h = plane.Height(p);
  const float band = InlierDistance(p.z(), options);
  if (!(h <= band && h >= -band)) return false;
  const float c = plane.normal.dot(grid.n[i]);
  return std::isnan(c) || c >= min_cos || c <= -min_cos;
}

// Least-squares (PCA) plane through the grid points of `indices`, turned
// towards the camera; nullopt for fewer than 3.
std::optional<Plane> FitPlane(const Grid& grid,
                              const std::vector<int>& indices);

// Plane-coordinate axes as SupportPlane documents them.
void SetAxes(SupportPlane& plane);
// Whether q lies inside the counter-clockwise hull, `margin` from its edges.
bool InsideHull(const std::vector<Eigen::Vector2f>& hull,
                const Eigen::Vector2f& q, float margin);
// Counter-clockwise convex hull of plane-coordinate points.
std::vector<Eigen::Vector2f> ConvexHull(
    const std::vector<Eigen::Vector2f>& points);
// Hull of the mask's pixels (every 4th row and column) in `plane`'s
// coordinates.
std::vector<Eigen::Vector2f> HullOfMask(const OrganizedCloud& cloud,
                                        const cv::Mat& mask,
                                        const SupportPlane& plane);
// The hull of the grid points `indices` in the frame's plane coordinates,
// from each grid row's leftmost and rightmost point only: the image and
// the plane are related by a homography, which keeps segments segments, so
// a row's other points lie between its two ends (up to the noise across
// the plane).
std::vector<Eigen::Vector2f> HullOfIndices(const Grid& grid,
                                           const SupportPlane& frame,
                                           const std::vector<int>& indices);

// The connected parts of `plane`'s near inliers (and of the grid points
// `also`): 8-connected on the grid where neighbours lie within 2.5 grid
// steps of each other in 3D (the inside of a bowl is not connected to the
// table past its rim). parts[0] is empty; `labels` (optional) gets each grid
// point's part (0 none).
std::vector<std::vector<int>> PlaneParts(const Grid& grid, const Plane& plane,
                                         const SupportPlaneOptions& options,
                                         float min_cos,
                                         const std::vector<int>& also,
                                         std::vector<int>* labels = nullptr);

// A candidate support surface.
struct Candidate {
  Plane plane;
  SupportPlane frame;        // plane, axes and hull only
  std::vector<int> indices;  // its grid points
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  float area_m2 = 0.0f;
  SupportScore score;
};

// The parts (PlaneParts) of `plane`'s near inliers with at least
// options.min_candidate_area_m2, each refitted by least squares when
// `refit`.
std::vector<Candidate> SplitIntoSurfaces(const Grid& grid, const Plane& plane,
                                         const SupportPlaneOptions& options,
                                         float min_cos, bool refit);

// Fills every candidate's score (SupportPlaneOptions) but its tilt and
// level term, which depend on which way is up: AddLevelTerm adds them.
void ScoreCandidates(const Grid& grid, const SupportPlaneOptions& options,
                     std::vector<Candidate>& candidates);

// Sets every candidate's tilt against `up` (gravity's opposite, or the
// normal the candidates chose) and adds its level term to its total.
void AddLevelTerm(const Eigen::Vector3f& up, const SupportPlaneOptions& options,
                  std::vector<Candidate>& candidates);

// The support region of `chosen`: its part of its plane joined by the
// plane's other parts that are inside its hull or only hidden from it by
// what stands in front (SupportPlaneOptions::max_occlusion_gap), refitted,
// with its full-resolution inliers and hull.
absl::StatusOr<SupportPlane> MakeSupportRegion(
    const OrganizedCloud& cloud, const Grid& grid, const Candidate& chosen,
    const SupportPlaneOptions& options, float min_cos);

// Labels the 8-connected components of the cells in `mask`: `labels`
// gets 1, 2, ... per component and 0 outside the mask; returns the next
// label (components + 1). `from(i)` gives, for cell i, the predicate
// `joins(j, diagonal)`: whether neighbour j (diagonal or not) lies on i's
// surface. Depth-first from each unlabelled cell in index order.
template <typename From>
int LabelGridComponents(const Grid& grid, const std::vector<uint8_t>& mask,
                        From from, std::vector<int>& labels) {
  labels.assign(grid.size(), 0);
  int next = 1;
  std::vector<int> stack;
  for (int seed = 0; seed < grid.size(); ++seed) {
    if (!mask[seed] || labels[seed] != 0) continue;
    labels[seed] = next;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const auto joins = from(i);
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
          if (!joins(j, dr != 0 && dc != 0)) continue;
          labels[j] = next;
          stack.push_back(j);
        }
      }
    }
    ++next;
  }
  return next;
}

}  // namespace fovea::support_internal

#endif  // FOVEA_CORE_SCENE_SUPPORT_GRID_H_
