#include "core/saliency/sh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// A candidate point in plane coordinates with its height.
struct PlanePoint {
  float x = 0.0f;
  float y = 0.0f;
  float height = 0.0f;
  int pixel = 0;  // v * width + u
};

// Points bucketed into square cells of size `cell` in plane coordinates
// (compressed sparse rows), each cell sorted by height, tallest first, so a
// query can stop at the first point in range.
struct PlaneGrid {
  float cell = 0.0f;
  float x0 = 0.0f, y0 = 0.0f;
  int nx = 0, ny = 0;
  std::vector<int> start;          // nx * ny + 1 offsets into `points`
  std::vector<PlanePoint> points;  // grouped by cell

  int CellX(float x) const { return static_cast<int>((x - x0) / cell); }
  int CellY(float y) const { return static_cast<int>((y - y0) / cell); }
};

PlaneGrid BuildGrid(const std::vector<PlanePoint>& pts, float cell) {
  PlaneGrid g;
  g.cell = cell;
  float x1 = pts[0].x, y1 = pts[0].y;
  g.x0 = x1;
  g.y0 = y1;
  for (const PlanePoint& p : pts) {
    g.x0 = std::min(g.x0, p.x);
    g.y0 = std::min(g.y0, p.y);
    x1 = std::max(x1, p.x);
    y1 = std::max(y1, p.y);
  }
  g.nx = g.CellX(x1) + 1;
  g.ny = g.CellY(y1) + 1;
  const size_t cells = static_cast<size_t>(g.nx) * g.ny;
  g.start.assign(cells + 1, 0);
  std::vector<int> cell_of(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    cell_of[i] = g.CellY(pts[i].y) * g.nx + g.CellX(pts[i].x);
    ++g.start[cell_of[i] + 1];
  }
  for (size_t c = 0; c < cells; ++c) g.start[c + 1] += g.start[c];
  g.points.resize(pts.size());
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (size_t i = 0; i < pts.size(); ++i) g.points[fill[cell_of[i]]++] = pts[i];
  for (size_t c = 0; c < cells; ++c) {
    std::sort(g.points.begin() + g.start[c], g.points.begin() + g.start[c + 1],
              [](const PlanePoint& a, const PlanePoint& b) {
                return a.height > b.height;
              });
  }
  return g;
}

// Largest height among the points within `radius` of (x, y).
float MaxHeightNear(const PlaneGrid& g, float x, float y, float radius) {
  const float r2 = radius * radius;
  const int cx = g.CellX(x), cy = g.CellY(y);
  float best = 0.0f;
  for (int j = std::max(cy - 1, 0); j <= std::min(cy + 1, g.ny - 1); ++j) {
    for (int i = std::max(cx - 1, 0); i <= std::min(cx + 1, g.nx - 1); ++i) {
      const int c = j * g.nx + i;
      for (int k = g.start[c]; k < g.start[c + 1]; ++k) {
        const PlanePoint& q = g.points[k];
        if (q.height <= best) break;  // sorted: nothing taller follows
        const float dx = q.x - x, dy = q.y - y;
        if (dx * dx + dy * dy <= r2) {
          best = q.height;
          break;
        }
      }
    }
  }
  return best;
}

}  // namespace

absl::Status Validate(const ShOptions& options) {
  if (!(options.radius > 0.0f && options.radius < 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sh.radius must be in (0, 1) metres, got ", options.radius));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeShSaliency(const OrganizedCloud& cloud,
                                          const SupportPlane& plane,
                                          const TableScene& scene,
                                          const ShOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  const int w = cloud.width(), h = cloud.height();
  cv::Mat map(h, w, CV_32FC1, cv::Scalar(0));
  std::vector<PlanePoint> pts;
  pts.reserve(scene.candidate_count);
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const float* height = scene.height.ptr<float>(v);
    const uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      if (!cand[u]) continue;
      const Eigen::Vector2f q = plane.ToPlane({p[u][0], p[u][1], p[u][2]});
      pts.push_back({q.x(), q.y(), height[u], v * w + u});
    }
  }
  if (pts.empty()) return map;
  const PlaneGrid grid = BuildGrid(pts, options.radius);
  float* out = map.ptr<float>(0);
  for (const PlanePoint& p : pts) {
    out[p.pixel] = MaxHeightNear(grid, p.x, p.y, options.radius);
  }
  NormalizeLinear(map);
  return map;
}

}  // namespace fovea
