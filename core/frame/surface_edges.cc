#include "core/frame/surface_edges.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"

namespace fovea {
namespace {

// Focal length the pixel radius is given at (a Kinect's).
constexpr double kReferenceFocalPx = 525.0;

// A threshold no finite value exceeds: turns a test off.
constexpr float kNever = std::numeric_limits<float>::infinity();

// The thresholds of SurfaceEdgeOptions, kNever for a test turned off.
struct PairTest {
  float jump_fraction;  // depth_jump_fraction
  float concave2;       // concave_curvature^2
  float min_curvature;  // concave_min_curvature
};

// For the `n` pairs (p[u], q[u]): out[u] |= bit where the pair lies on two
// surfaces (a depth jump, or a sharp concave crease: SurfaceEdgeOptions).
// p and q point into rows of six planes `stride` floats apart: x, y, z,
// then the normal's x, y, z. Without branches, so that it vectorises:
// every comparison with a NaN is false, so a pixel without a point or a
// normal makes no edge, and a test with an infinite threshold never fires.
void MarkPairs(const float* __restrict p, const float* __restrict q, int stride,
               int n, PairTest test, uint8_t bit, uint8_t* __restrict out) {
  const float* __restrict px = p;
  const float* __restrict py = p + stride;
  const float* __restrict pz = p + 2 * stride;
  const float* __restrict pnx = p + 3 * stride;
  const float* __restrict pny = p + 4 * stride;
  const float* __restrict pnz = p + 5 * stride;
  const float* __restrict qx = q;
  const float* __restrict qy = q + stride;
  const float* __restrict qz = q + 2 * stride;
  const float* __restrict qnx = q + 3 * stride;
  const float* __restrict qny = q + 4 * stride;
  const float* __restrict qnz = q + 5 * stride;
  for (int u = 0; u < n; ++u) {
    const float nearer = pz[u] < qz[u] ? pz[u] : qz[u];
    const float dx = qx[u] - px[u], dy = qy[u] - py[u], dz = qz[u] - pz[u];
    const bool jump = (dz < 0.0f ? -dz : dz) > test.jump_fraction * nearer;
    const float len2 = dx * dx + dy * dy + dz * dz;
    const float dn = (qnx[u] - pnx[u]) * dx + (qny[u] - pny[u]) * dy +
                     (qnz[u] - pnz[u]) * dz;
    // dn / |d| < -c without the square root: dn < 0 and dn^2 > c^2 |d|^2.
    const bool crease = (dn < 0.0f) & (dn * dn > test.concave2 * len2) &
                        (-dn > test.min_curvature * len2);
    out[u] |= (jump | crease) ? bit : 0;
  }
}

}  // namespace

absl::Status Validate(const SurfaceEdgeOptions& options) {
  if (options.radius_px < 1 || options.radius_px > 16) {
    return absl::InvalidArgumentError(absl::StrCat(
        "surface_edges.radius_px must be in [1, 16], got ", options.radius_px));
  }
  if (!(options.depth_jump_fraction >= 0.0f &&
        options.depth_jump_fraction <= 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface_edges.depth_jump_fraction must be in [0, 1], "
                     "got ",
                     options.depth_jump_fraction));
  }
  if (!(options.concave_curvature >= 0.0f &&
        options.concave_curvature <= 2.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface_edges.concave_curvature must be in [0, 2], got ",
                     options.concave_curvature));
  }
  if (!(options.concave_min_curvature >= 0.0f &&
        options.concave_min_curvature <= 1000.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "surface_edges.concave_min_curvature must be in [0, 1000] 1/m, got ",
        options.concave_min_curvature));
  }
  return absl::OkStatus();
}

cv::Mat FindSurfaceEdges(const OrganizedCloud& cloud,
                         const SurfaceEdgeOptions& options) {
  const int w = cloud.width(), h = cloud.height();
  const int r = std::max(
      1, static_cast<int>(std::lround(options.radius_px * cloud.intrinsics.fx /
                                      kReferenceFocalPx)));
  // Half of the neighbourhood (right, down, down-right, down-left); each
  // pair is tested once, and both ends are marked.
  const std::array<cv::Point, 4> steps = {cv::Point(r, 0), cv::Point(0, r),
                                          cv::Point(r, r), cv::Point(-r, r)};
  const bool jumps = options.depth_jump_fraction > 0.0f;
  const bool creases = options.concave_curvature > 0.0f;
  const float concave2 = options.concave_curvature * options.concave_curvature;
  const PairTest test{jumps ? options.depth_jump_fraction : kNever,
                      creases ? concave2 : kNever,
                      options.concave_min_curvature};
  // First, bit k of pairs(v, u): p = (u, v) and q = p + steps[k] are on two
  // surfaces. Rows in parallel: each writes its own row. Each range keeps
  // the rows it reads as six planes of floats (x, y, z and the normal's),
  // a ring of the r + 1 rows from v to v + r, so that the pair test runs
  // on contiguous arrays and vectorises.
  cv::Mat pairs(h, w, CV_8UC1, cv::Scalar(0));
  ParallelForRanges(h, [&](int begin, int end) {
    const int ring_rows = r + 1;
    std::vector<float> ring(static_cast<size_t>(ring_rows) * 6 * w);
    std::vector<int> held(ring_rows, -1);  // the row in each slot
    const auto planes = [&](int y) {
      float* planes = &ring[static_cast<size_t>(y % ring_rows) * 6 * w];
      if (held[y % ring_rows] != y) {
        held[y % ring_rows] = y;
        const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(y);
        const cv::Vec3f* nrm = cloud.normals.ptr<cv::Vec3f>(y);
        for (int c = 0; c < 3; ++c) {
          float* point = planes + c * w;
          float* normal = planes + (3 + c) * w;
          for (int u = 0; u < w; ++u) {
            point[u] = xyz[u][c];
            normal[u] = nrm[u][c];
          }
        }
      }
      return static_cast<const float*>(planes);
    };
    for (int v = begin; v < end; ++v) {
      uint8_t* bits = pairs.ptr<uint8_t>(v);
      for (int k = 0; k < 4; ++k) {
        const cv::Point& s = steps[k];
        if (v + s.y >= h) continue;
        const float* p = planes(v);
        const float* q = planes(v + s.y);
        const int u_begin = std::max(0, -s.x);
        const int u_end = std::min(w, w - s.x);
        MarkPairs(p + u_begin, q + u_begin + s.x, w, u_end - u_begin, test,
                  static_cast<uint8_t>(1u << k), bits + u_begin);
      }
    }
  });
  // Then a pixel is an edge when a pair it starts or ends is.
  cv::Mat edges(h, w, CV_8UC1, cv::Scalar(0));
  ParallelForRanges(h, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      uint8_t* out = edges.ptr<uint8_t>(v);
      const uint8_t* own = pairs.ptr<uint8_t>(v);
      for (int u = 0; u < w; ++u) out[u] = own[u] != 0 ? 255 : 0;
      for (int k = 0; k < 4; ++k) {
        const cv::Point& s = steps[k];
        if (v - s.y < 0) continue;
        const uint8_t bit = static_cast<uint8_t>(1u << k);
        const uint8_t* from = pairs.ptr<uint8_t>(v - s.y);
        const int u_begin = std::max(0, s.x);
        const int u_end = std::min(w, w + s.x);
        for (int u = u_begin; u < u_end; ++u) {
          if (from[u - s.x] & bit) out[u] = 255;
        }
      }
    }
  });
  return edges;
}

}  // namespace fovea
