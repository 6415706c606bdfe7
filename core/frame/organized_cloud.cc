#include "core/frame/organized_cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Integral images of x, y, z and the count of valid points, (h+1) x (w+1),
// in double so that sums over a 640x480 frame stay exact to well below a
// millimetre.
struct PointIntegrals {
  int width = 0;
  int height = 0;
  std::vector<double> sx, sy, sz;
  std::vector<int> count;

  size_t Index(int u, int v) const {
    return static_cast<size_t>(v) * (width + 1) + u;
  }
};

PointIntegrals IntegratePoints(const cv::Mat& xyz) {
  PointIntegrals in;
  in.width = xyz.cols;
  in.height = xyz.rows;
  const size_t n = static_cast<size_t>(in.width + 1) * (in.height + 1);
  in.sx.assign(n, 0.0);
  in.sy.assign(n, 0.0);
  in.sz.assign(n, 0.0);
  in.count.assign(n, 0);
  for (int v = 0; v < in.height; ++v) {
    const cv::Vec3f* row = xyz.ptr<cv::Vec3f>(v);
    double rx = 0, ry = 0, rz = 0;
    int rc = 0;
    const size_t above = in.Index(0, v);
    const size_t here = in.Index(0, v + 1);
    for (int u = 0; u < in.width; ++u) {
      const cv::Vec3f& p = row[u];
      if (!std::isnan(p[2])) {
        rx += p[0];
        ry += p[1];
        rz += p[2];
        ++rc;
      }
      in.sx[here + u + 1] = in.sx[above + u + 1] + rx;
      in.sy[here + u + 1] = in.sy[above + u + 1] + ry;
      in.sz[here + u + 1] = in.sz[above + u + 1] + rz;
      in.count[here + u + 1] = in.count[above + u + 1] + rc;
    }
  }
  return in;
}

// Mean of the valid points in the window [u0, u1] x [v0, v1] (inclusive,
// clipped by the caller). False when the window holds no valid point.
bool BoxMean(const PointIntegrals& in, int u0, int v0, int u1, int v1,
             cv::Vec3d& mean) {
  const size_t a = in.Index(u0, v0), b = in.Index(u1 + 1, v0),
               c = in.Index(u0, v1 + 1), d = in.Index(u1 + 1, v1 + 1);
  const int n = in.count[d] - in.count[b] - in.count[c] + in.count[a];
  if (n <= 0) return false;
  const double inv = 1.0 / n;
  mean = {(in.sx[d] - in.sx[b] - in.sx[c] + in.sx[a]) * inv,
          (in.sy[d] - in.sy[b] - in.sy[c] + in.sy[a]) * inv,
          (in.sz[d] - in.sz[b] - in.sz[c] + in.sz[a]) * inv};
  return true;
}

int HalfWindow(const NormalOptions& options, float z) {
  const int r = static_cast<int>(std::lround(options.smoothing_px_at_1m / z));
  return std::clamp(r, options.min_half_window, options.max_half_window);
}

}  // namespace

absl::Status Validate(const NormalOptions& options) {
  if (!(options.smoothing_px_at_1m > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("normals.smoothing_px_at_1m must be > 0, got ",
                     options.smoothing_px_at_1m));
  }
  if (options.min_half_window < 1 ||
      options.max_half_window < options.min_half_window) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normals.min_half_window/max_half_window must satisfy 1 <= min <= "
        "max, got ",
        options.min_half_window, " and ", options.max_half_window));
  }
  if (!(options.max_depth_change_factor > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("normals.max_depth_change_factor must be > 0, got ",
                     options.max_depth_change_factor));
  }
  return absl::OkStatus();
}

OrganizedCloud BackProject(const RgbdFrame& frame) {
  OrganizedCloud cloud;
  cloud.intrinsics = frame.intrinsics;
  cloud.color = frame.color;
  const int w = frame.width(), h = frame.height();
  cloud.xyz.create(h, w, CV_32FC3);
  cloud.normals.create(h, w, CV_32FC3);
  cloud.normals.setTo(cv::Scalar::all(kNaN));
  const float inv_fx = static_cast<float>(1.0 / frame.intrinsics.fx);
  const float inv_fy = static_cast<float>(1.0 / frame.intrinsics.fy);
  const float cx = static_cast<float>(frame.intrinsics.cx);
  const float cy = static_cast<float>(frame.intrinsics.cy);
  for (int v = 0; v < h; ++v) {
    const float* depth = frame.depth.ptr<float>(v);
    cv::Vec3f* out = cloud.xyz.ptr<cv::Vec3f>(v);
    const float ny = (static_cast<float>(v) - cy) * inv_fy;
    for (int u = 0; u < w; ++u) {
      const float z = depth[u];
      if (std::isnan(z)) {
        out[u] = {kNaN, kNaN, kNaN};
      } else {
        out[u] = {(static_cast<float>(u) - cx) * inv_fx * z, ny * z, z};
      }
    }
  }
  return cloud;
}

void EstimateNormals(const NormalOptions& options, OrganizedCloud& cloud) {
  const int w = cloud.width(), h = cloud.height();
  cloud.normals.create(h, w, CV_32FC3);
  const PointIntegrals in = IntegratePoints(cloud.xyz);
  auto smoothed = [&](int u, int v, int r, cv::Vec3d& mean) {
    return BoxMean(in, std::max(u - r, 0), std::max(v - r, 0),
                   std::min(u + r, w - 1), std::min(v + r, h - 1), mean);
  };
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* row = cloud.xyz.ptr<cv::Vec3f>(v);
    cv::Vec3f* out = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < w; ++u) {
      out[u] = {kNaN, kNaN, kNaN};
      const float z = row[u][2];
      if (std::isnan(z)) continue;
      const int r = HalfWindow(options, z);
      if (u - r < 0 || u + r >= w || v - r < 0 || v + r >= h) continue;
      // The four samples must lie on the same surface as the centre.
      const float max_change = options.max_depth_change_factor * z * r;
      const float zl = row[u - r][2], zr = row[u + r][2];
      const float zu = cloud.xyz.ptr<cv::Vec3f>(v - r)[u][2];
      const float zd = cloud.xyz.ptr<cv::Vec3f>(v + r)[u][2];
      if (!(std::abs(zl - z) <= max_change && std::abs(zr - z) <= max_change &&
            std::abs(zu - z) <= max_change && std::abs(zd - z) <= max_change)) {
        continue;
      }
      const int s = std::max(r / 2, 1);  // smoothing half window
      cv::Vec3d left, right, up, down;
      if (!smoothed(u - r, v, s, left) || !smoothed(u + r, v, s, right) ||
          !smoothed(u, v - r, s, up) || !smoothed(u, v + r, s, down)) {
        continue;
      }
      const cv::Vec3d gu = right - left;
      const cv::Vec3d gv = down - up;
      cv::Vec3d n = gv.cross(gu);
      const double norm = cv::norm(n);
      if (!(norm > 0.0)) continue;
      n *= 1.0 / norm;
      // Orient towards the camera (the origin): n . p < 0.
      if (n[0] * row[u][0] + n[1] * row[u][1] + n[2] * z > 0.0) n = -n;
      out[u] = cv::Vec3f(static_cast<float>(n[0]), static_cast<float>(n[1]),
                         static_cast<float>(n[2]));
    }
  }
}

absl::StatusOr<OrganizedCloud> BuildOrganizedCloud(
    const RgbdFrame& frame, const NormalOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  if (frame.depth.empty() || frame.depth.type() != CV_32FC1) {
    return absl::InvalidArgumentError("frame.depth: expected CV_32FC1 metres");
  }
  OrganizedCloud cloud = BackProject(frame);
  EstimateNormals(options, cloud);
  return cloud;
}

}  // namespace fovea
