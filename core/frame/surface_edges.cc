#include "core/frame/surface_edges.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"

namespace fovea {
namespace {

// Focal length the pixel radius is given at (a Kinect's).
constexpr double kReferenceFocalPx = 525.0;

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
  // First, bit k of pairs(v, u): p = (u, v) and q = p + steps[k] are on two
  // surfaces. Rows in parallel: each writes its own row.
  cv::Mat pairs(h, w, CV_8UC1, cv::Scalar(0));
  ParallelForRanges(h, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const cv::Vec3f* p_xyz = cloud.xyz.ptr<cv::Vec3f>(v);
      const cv::Vec3f* p_nrm = cloud.normals.ptr<cv::Vec3f>(v);
      uint8_t* bits = pairs.ptr<uint8_t>(v);
      for (int k = 0; k < 4; ++k) {
        const cv::Point& s = steps[k];
        if (v + s.y >= h) continue;
        const cv::Vec3f* q_xyz = cloud.xyz.ptr<cv::Vec3f>(v + s.y) + s.x;
        const cv::Vec3f* q_nrm = cloud.normals.ptr<cv::Vec3f>(v + s.y) + s.x;
        const uint8_t bit = static_cast<uint8_t>(1u << k);
        const int u_begin = std::max(0, -s.x);
        const int u_end = std::min(w, w - s.x);
        for (int u = u_begin; u < u_end; ++u) {
          const cv::Vec3f& p = p_xyz[u];
          const cv::Vec3f& q = q_xyz[u];
          if (std::isnan(p[2]) || std::isnan(q[2])) continue;
          bool edge = false;
          if (jumps && std::abs(q[2] - p[2]) >
                           options.depth_jump_fraction * std::min(p[2], q[2])) {
            edge = true;
          } else if (creases && !std::isnan(p_nrm[u][2]) &&
                     !std::isnan(q_nrm[u][2])) {
            const cv::Vec3f d = q - p;
            const float len2 = d.dot(d);
            const float dn = (q_nrm[u] - p_nrm[u]).dot(d);
            // dn / |d| < -c without the square root: dn < 0 and
            // dn^2 > c^2 |d|^2.
            edge = dn < 0.0f && dn * dn > concave2 * len2 &&
                   -dn > options.concave_min_curvature * len2;
          }
          if (edge) bits[u] |= bit;
        }
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
