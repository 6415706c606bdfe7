#include "core/saliency/sh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
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

// A dense cell table is used while it has at most this many cells per
// point (and at least kMinDenseCells); beyond that (a table kilometres
// wide from implausible geometry) cells are hashed, so memory stays
// proportional to the number of points whatever the input.
constexpr int64_t kDenseCellsPerPoint = 16;
constexpr int64_t kMinDenseCells = 1 << 16;

// Points bucketed into square cells of size `cell` in plane coordinates,
// grouped by cell and each cell sorted by height, tallest first, so a
// query can stop at the first point in range.
class PlaneGrid {
 public:
  PlaneGrid(const std::vector<PlanePoint>& pts, float cell) : cell_(cell) {
    x0_ = y0_ = std::numeric_limits<float>::max();
    float x1 = std::numeric_limits<float>::lowest(), y1 = x1;
    for (const PlanePoint& p : pts) {
      x0_ = std::min(x0_, p.x);
      y0_ = std::min(y0_, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
    nx_ = CellX(x1) + 1;
    ny_ = CellY(y1) + 1;
    const int64_t cells = nx_ * ny_;
    dense_ = cells <= std::max<int64_t>(kMinDenseCells,
                                        kDenseCellsPerPoint *
                                            static_cast<int64_t>(pts.size()));
    std::vector<int64_t> key(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      key[i] = CellY(pts[i].y) * nx_ + CellX(pts[i].x);
    }
    std::vector<int> order(pts.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return key[a] != key[b] ? key[a] < key[b] : pts[a].height > pts[b].height;
    });
    points_.reserve(pts.size());
    for (int i : order) points_.push_back(pts[i]);
    if (dense_) {
      // Counting offsets: cell c spans [start_[c], start_[c + 1]).
      start_.assign(static_cast<size_t>(cells) + 1, 0);
      for (int64_t k : key) ++start_[k + 1];
      for (int64_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
      return;
    }
    for (size_t k = 0; k < order.size();) {
      const int64_t c = key[order[k]];
      size_t end = k;
      while (end < order.size() && key[order[end]] == c) ++end;
      sparse_[c] = {static_cast<int>(k), static_cast<int>(end)};
      k = end;
    }
  }

  // Largest height among the points within `radius` of (x, y).
  float MaxHeightNear(float x, float y, float radius) const {
    const float r2 = radius * radius;
    const int64_t cx = CellX(x), cy = CellY(y);
    float best = 0.0f;
    for (int64_t j = std::max<int64_t>(cy - 1, 0);
         j <= std::min<int64_t>(cy + 1, ny_ - 1); ++j) {
      for (int64_t i = std::max<int64_t>(cx - 1, 0);
           i <= std::min<int64_t>(cx + 1, nx_ - 1); ++i) {
        const auto [begin, end] = Range(j * nx_ + i);
        for (int k = begin; k < end; ++k) {
          const PlanePoint& q = points_[k];
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

 private:
  int64_t CellX(float x) const {
    return static_cast<int64_t>((static_cast<double>(x) - x0_) / cell_);
  }
  int64_t CellY(float y) const {
    return static_cast<int64_t>((static_cast<double>(y) - y0_) / cell_);
  }

  std::pair<int, int> Range(int64_t c) const {
    if (dense_) return {start_[c], start_[c + 1]};
    const auto it = sparse_.find(c);
    return it == sparse_.end() ? std::pair<int, int>{0, 0} : it->second;
  }

  float cell_ = 0.0f;
  float x0_ = 0.0f, y0_ = 0.0f;
  int64_t nx_ = 0, ny_ = 0;
  bool dense_ = true;
  std::vector<PlanePoint> points_;  // grouped by cell, tallest first
  std::vector<int> start_;          // dense: nx * ny + 1 offsets
  absl::flat_hash_map<int64_t, std::pair<int, int>> sparse_;
};

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
  FOVEA_RETURN_IF_ERROR(Validate(options));
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
  const PlaneGrid grid(pts, options.radius);
  float* out = map.ptr<float>(0);
  for (const PlanePoint& p : pts) {
    out[p.pixel] = grid.MaxHeightNear(p.x, p.y, options.radius);
  }
  NormalizeLinear(map);
  return map;
}

}  // namespace fovea
