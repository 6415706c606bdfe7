#include "core/scene/table_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/scene/hull_lookup.h"
#include "core/scene/table_scene_internal.h"

namespace fovea {

absl::Status Validate(const TableSceneOptions& options) {
  if (!(options.min_object_height >= 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("table_scene.min_object_height must be >= 0, got ",
                     options.min_object_height));
  }
  if (!(options.max_object_height > options.min_object_height)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "table_scene.max_object_height must exceed min_object_height, got ",
        options.max_object_height));
  }
  if (!(options.min_height_sigmas >= 0.0f) || !(options.sigma0_m >= 0.0f) ||
      !(options.sigma_per_z2 >= 0.0f)) {
    return absl::InvalidArgumentError(
        "table_scene.min_height_sigmas, sigma0_m and sigma_per_z2 must be >= "
        "0");
  }
  if (!(options.structure_tolerance_deg >= 0.0f &&
        options.structure_tolerance_deg <= 90.0f) ||
      !(options.structure_min_area_m2 >= 0.0f) ||
      options.structure_max_planes < 0) {
    return absl::InvalidArgumentError(
        "table_scene.structure_tolerance_deg must be in [0, 90], "
        "structure_min_area_m2 and structure_max_planes >= 0");
  }
  if (!(options.rest_beyond_hull_m >= 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("table_scene.rest_beyond_hull_m must be >= 0, got ",
                     options.rest_beyond_hull_m));
  }
  if (!(options.max_resting_size_m > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("table_scene.max_resting_size_m must be > 0, got ",
                     options.max_resting_size_m));
  }
  if (!(options.hull_margin >= 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "table_scene.hull_margin must be >= 0, got ", options.hull_margin));
  }
  return absl::OkStatus();
}

namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// The structure search: on every stride-th pixel of a frame at most this
// many columns wide; hypotheses per plane (a point and its normal);
// inliers within this band (at least) with normals within this angle.
constexpr int kStructureGridColumns = 160;
constexpr int kStructureHypotheses = 60;
constexpr float kStructureBand = 0.012f;       // metres
constexpr float kStructureNormalCos = 0.906f;  // 25 degrees
// Below the table by more than this counts as beyond it, metres.
constexpr float kBelowTable = 0.05f;

float Band(float z, const TableSceneOptions& o) {
  return std::max(kStructureBand,
                  o.min_height_sigmas * (o.sigma0_m + o.sigma_per_z2 * z * z));
}

struct StructureSample {
  Eigen::Vector3f p, n;
  float area = 0.0f;  // m^2 the sample stands for
};

// Vertical planes with enough area beyond the table: sequential RANSAC
// over the samples beyond it whose normals are horizontal.
std::vector<TableScene::Plane> FindStructures(const OrganizedCloud& cloud,
                                              const SupportPlane& plane,
                                              const TableSceneOptions& o) {
  std::vector<TableScene::Plane> structures;
  if (o.structure_max_planes <= 0) return structures;
  const int stride = std::max(
      1, (cloud.width() + kStructureGridColumns - 1) / kStructureGridColumns);
  const float max_up = std::sin(o.structure_tolerance_deg * kDegToRad);
  const double pixel = static_cast<double>(stride) * stride /
                       (cloud.intrinsics.fx * cloud.intrinsics.fy);
  std::vector<StructureSample> beyond;
  for (int v = 0; v < cloud.height(); v += stride) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); u += stride) {
      if (std::isnan(p[u][2]) || std::isnan(n[u][2])) continue;
      const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
      const Eigen::Vector3f m(n[u][0], n[u][1], n[u][2]);
      if (std::abs(m.dot(plane.normal)) > max_up) continue;
      const float h = plane.Height(q);
      if (h <= o.max_object_height && h >= -kBelowTable &&
          plane.ProjectsInsideHull(q)) {
        continue;
      }
      const float incidence = std::max(0.2f, std::abs(m.dot(q)) / q.norm());
      beyond.push_back(
          {q, m, static_cast<float>(pixel * q.z() * q.z() / incidence)});
    }
  }
  uint32_t state = 12345u;  // a small LCG: deterministic, no <random>
  auto next = [&state](size_t n) {
    state = state * 1664525u + 1013904223u;
    return static_cast<size_t>(state >> 8) % n;
  };
  for (int round = 0; round < o.structure_max_planes && !beyond.empty();
       ++round) {
    float best_area = 0.0f;
    TableScene::Plane best;
    for (int k = 0; k < kStructureHypotheses; ++k) {
      const StructureSample& s = beyond[next(beyond.size())];
      const TableScene::Plane h{s.n, -s.n.dot(s.p)};
      float area = 0.0f;
      for (const StructureSample& t : beyond) {
        if (std::abs(h.normal.dot(t.p) + h.d) <= Band(t.p.z(), o) &&
            std::abs(h.normal.dot(t.n)) >= kStructureNormalCos) {
          area += t.area;
        }
      }
      if (area > best_area) {
        best_area = area;
        best = h;
      }
    }
    if (best_area < o.structure_min_area_m2) break;
    structures.push_back(best);
    std::vector<StructureSample> rest;
    for (const StructureSample& t : beyond) {
      if (!(std::abs(best.normal.dot(t.p) + best.d) <= Band(t.p.z(), o))) {
        rest.push_back(t);
      }
    }
    beyond.swap(rest);
  }
  return structures;
}

}  // namespace

namespace table_scene_internal {

// Whether p (normal m, NaN when none) lies on one of the structures.
bool OnStructure(const std::vector<TableScene::Plane>& structures,
                 const Eigen::Vector3f& p, const cv::Vec3f& m,
                 const TableSceneOptions& o) {
  for (const TableScene::Plane& s : structures) {
    if (!(std::abs(s.normal.dot(p) + s.d) <= Band(p.z(), o))) continue;
    if (std::isnan(m[2]) ||
        std::abs(s.normal.x() * m[0] + s.normal.y() * m[1] +
                 s.normal.z() * m[2]) >= kStructureNormalCos) {
      return true;
    }
  }
  return false;
}

}  // namespace table_scene_internal

using table_scene_internal::AddWhatRestsBeyondHull;
using table_scene_internal::OnStructure;
using table_scene_internal::TableNoiseBand;

TableScene PrepareTableScene(const OrganizedCloud& cloud,
                             const SupportPlane& plane,
                             const TableSceneOptions& options) {
  TableScene scene;
  scene.structures = FindStructures(cloud, plane, options);
  const int w = cloud.width(), h = cloud.height();
  scene.height.create(h, w, CV_32FC1);
  scene.candidate.create(h, w, CV_8UC1);
  scene.candidate.setTo(cv::Scalar(0));
  scene.region.create(h, w, CV_8UC1);
  scene.region.setTo(cv::Scalar(0));
  scene.standing.create(h, w, CV_8UC1);
  scene.standing.setTo(cv::Scalar(0));
  const bool have_inliers = plane.inliers.rows == h && plane.inliers.cols == w;
  const Eigen::Vector3f& n = plane.normal;
  const HullLookup in_hull(plane, 0.0f);
  const HullLookup in_hull_by_margin(plane, options.hull_margin);
  // Rows in parallel ranges; each range counts its own candidates.
  std::vector<int> candidates(h, 0);
  // Per row, the points above the table's noise band outside its hull:
  // without any, nothing can rest beyond it and that search is skipped.
  std::vector<int> beyond(h, 0);
  ParallelForRanges(h, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
      const cv::Vec3f* normals = cloud.normals.ptr<cv::Vec3f>(v);
      float* height = scene.height.ptr<float>(v);
      uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
      uint8_t* region = scene.region.ptr<uint8_t>(v);
      uint8_t* standing = scene.standing.ptr<uint8_t>(v);
      const uint8_t* inlier =
          have_inliers ? plane.inliers.ptr<uint8_t>(v) : nullptr;
      for (int u = 0; u < w; ++u) {
        if (std::isnan(p[u][2])) {
          height[u] = std::numeric_limits<float>::quiet_NaN();
          continue;
        }
        const float hgt =
            n.x() * p[u][0] + n.y() * p[u][1] + n.z() * p[u][2] + plane.d;
        height[u] = hgt;
        const float z = p[u][2];
        const float min_height = TableNoiseBand(z, options);
        const bool on_plane = inlier != nullptr && inlier[u];
        if (on_plane) region[u] = 255;
        if (hgt > options.max_object_height) continue;
        if (hgt <= min_height && (on_plane || hgt < -min_height)) continue;
        const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
        if (!in_hull.Contains(q)) {
          if (hgt > min_height) ++beyond[v];
          continue;
        }
        if (!scene.structures.empty() &&
            OnStructure(scene.structures, q, normals[u], options)) {
          continue;
        }
        region[u] = 255;
        if (hgt <= min_height) continue;
        standing[u] = 255;
        if (in_hull_by_margin.Contains(q)) {
          cand[u] = 255;
          ++candidates[v];
        }
      }
    }
  });
  for (const int c : candidates) scene.candidate_count += c;
  if (std::any_of(beyond.begin(), beyond.end(), [](int n) { return n > 0; })) {
    AddWhatRestsBeyondHull(cloud, plane, options, scene);
  }
  return scene;
}

}  // namespace fovea
