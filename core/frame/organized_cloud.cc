#include "core/frame/organized_cloud.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The cloud box-smoothed over valid points only: the mean of the valid
// points in the (2 * half + 1)^2 window around each pixel, NaN where the
// window holds none. Separable running sums in double (as OpenCV's box
// filter of a float image sums), rows in parallel ranges: each range sums
// the rows it needs along u, then those down v.
cv::Mat SmoothValidPoints(const cv::Mat& xyz, int half) {
  const int h = xyz.rows, w = xyz.cols;
  const int window = 2 * half + 1;
  cv::Mat points(h, w, CV_32FC3);
  ParallelForRanges(h, [&](int begin, int end) {
    std::vector<cv::Vec4d> valid(w);
    // (x, y, z, count) of row y's valid points summed along the row, by
    // running sums: add the pixel entering the window, take away the one
    // leaving it.
    const auto sum_along = [&](int y, cv::Vec4d* out) {
      const cv::Vec3f* in = xyz.ptr<cv::Vec3f>(y);
      for (int u = 0; u < w; ++u) {
        valid[u] = std::isnan(in[u][2])
                       ? cv::Vec4d(0.0, 0.0, 0.0, 0.0)
                       : cv::Vec4d(in[u][0], in[u][1], in[u][2], 1.0);
      }
      cv::Vec4d sum(0.0, 0.0, 0.0, 0.0);
      for (int k = 0; k < std::min(w, half); ++k) sum += valid[k];
      for (int u = 0; u < w; ++u) {
        if (u + half < w) sum += valid[u + half];
        if (u - half - 1 >= 0) sum -= valid[u - half - 1];
        out[u] = sum;
      }
    };
    // The same down the columns, keeping the last `window` rows' sums in a
    // ring (row y in slot y % window).
    std::vector<cv::Vec4d> ring(static_cast<size_t>(window) * w);
    std::vector<cv::Vec4d> entering(w);
    std::vector<cv::Vec4d> column(w, cv::Vec4d(0.0, 0.0, 0.0, 0.0));
    const auto slot = [&](int y) {
      return &ring[static_cast<size_t>(y % window) * w];
    };
    const int top = std::max(0, begin - half);
    for (int y = top; y < std::min(h, begin + half); ++y) {
      sum_along(y, slot(y));
      for (int u = 0; u < w; ++u) column[u] += slot(y)[u];
    }
    for (int v = begin; v < end; ++v) {
      const bool enter = v + half < h;
      const bool leave = v - half - 1 >= top;
      if (enter) sum_along(v + half, entering.data());
      const cv::Vec4d* leaving = leave ? slot(v - half - 1) : nullptr;
      cv::Vec3f* out = points.ptr<cv::Vec3f>(v);
      for (int u = 0; u < w; ++u) {
        if (enter) column[u] += entering[u];
        if (leave) column[u] -= leaving[u];
        const cv::Vec4d& sum = column[u];
        const float count = static_cast<float>(sum[3]);
        if (count > 0.5f) {
          const float inverse = 1.0f / count;
          out[u] = {static_cast<float>(sum[0]) * inverse,
                    static_cast<float>(sum[1]) * inverse,
                    static_cast<float>(sum[2]) * inverse};
        } else {
          out[u] = {kNaN, kNaN, kNaN};
        }
      }
      // Row v + half takes the slot of row v - half - 1, which has left.
      if (enter) std::copy(entering.begin(), entering.end(), slot(v + half));
    }
  });
  return points;
}

// Focal length the pixel options are given for (Kinect v1).
constexpr double kReferenceFocalPx = 525.0;

int HalfWindow(const NormalOptions& options, float focal_px, float z) {
  const int r =
      static_cast<int>(std::lround(options.baseline_m * focal_px / z));
  return std::clamp(r, options.min_half_window, options.max_half_window);
}

// Gaps of at most this many pixels are bridged (BackProject).
constexpr int kMaxBridgedGap = 2;
// Steepest surface a gap is bridged on, as the tangent of the angle
// between its normal and the viewing ray: a surface at that angle changes
// depth by z * tan / f per pixel, so 5 (79 degrees) bridges surfaces seen
// at a grazing angle and leaves a depth step at an object's edge
// unbridged: at 1 m on a Kinect, a step of 2 cm across a one-pixel gap.
constexpr float kMaxBridgedTangent = 5.0f;
// Gaps are bridged only when they would add at least this share of the
// frame's points: a sensor's regular dropouts (every other or every 4th
// column or row) add a third or more, while the thin gaps of ordinary
// frames (at edges, on dark objects) add well under 1 %: 0.03 % on
// Kinect frames, 0.04-0.24 % on RealSense office frames, at most 3 % on
// synthetic piles with dark objects. Those frames stay exactly as sent.
constexpr double kMinBridgedShare = 0.10;
// The share is estimated on every kShareSampling-th row and column.
constexpr int kShareSampling = 4;

// Walks the runs of at most kMaxBridgedGap pixels without depth along one
// line (`count` pixels `step` apart in memory, from `line`) whose two ends
// lie on one surface; bridges them when `bridge`, else only counts them.
// Returns the number of pixels bridged (or that would be). `focal` is the
// focal length along the line, pixels.
int WalkThinGaps(cv::Vec3f* line, int count, int step, float focal,
                 bool bridge) {
  const float slope = kMaxBridgedTangent / focal;
  int bridged = 0;
  int last_valid = -1;
  for (int i = 0; i < count; ++i) {
    const cv::Vec3f& p = line[i * step];
    if (std::isnan(p[2])) continue;
    const int gap = i - last_valid - 1;
    if (last_valid >= 0 && gap >= 1 && gap <= kMaxBridgedGap) {
      const cv::Vec3f& a = line[last_valid * step];
      const float z = std::min(a[2], p[2]);
      if (std::abs(a[2] - p[2]) <= slope * z * static_cast<float>(gap + 1)) {
        bridged += gap;
        if (bridge) {
          // Each pixel's ray (x/z, y/z) is linear along the line, and so is
          // 1/z on a plane: the bridge is the plane through the two ends.
          const cv::Vec3f ray_a = a * (1.0f / a[2]);
          const cv::Vec3f ray_p = p * (1.0f / p[2]);
          for (int k = 1; k <= gap; ++k) {
            const float t = static_cast<float>(k) / static_cast<float>(gap + 1);
            const float inverse_z = (1.0f - t) / a[2] + t / p[2];
            line[(last_valid + k) * step] =
                (ray_a + t * (ray_p - ray_a)) * (1.0f / inverse_z);
          }
        }
      }
    }
    last_valid = i;
  }
  return bridged;
}

// Bridges thin gaps along every row, then along every column (a pixel
// missing in both directions takes its column's ends, which the row pass
// may have made), when they are a regular pattern (kMinBridgedShare).
void BridgeThinGaps(const Intrinsics& intrinsics, cv::Mat& xyz) {
  CV_Assert(xyz.isContinuous());
  cv::Vec3f* data = xyz.ptr<cv::Vec3f>(0);
  const int w = xyz.cols, h = xyz.rows;
  const auto fx = static_cast<float>(intrinsics.fx);
  const auto fy = static_cast<float>(intrinsics.fy);
  int64_t sampled_points = 0;
  int64_t sampled_gaps = 0;
  for (int v = 0; v < h; v += kShareSampling) {
    const cv::Vec3f* row = data + static_cast<ptrdiff_t>(v) * w;
    for (int u = 0; u < w; ++u) sampled_points += !std::isnan(row[u][2]);
    sampled_gaps += WalkThinGaps(data + static_cast<ptrdiff_t>(v) * w, w, 1, fx,
                                 /*bridge=*/false);
  }
  for (int u = 0; u < w; u += kShareSampling) {
    for (int v = 0; v < h; ++v) {
      sampled_points += !std::isnan(data[static_cast<ptrdiff_t>(v) * w + u][2]);
    }
    sampled_gaps += WalkThinGaps(data + u, h, w, fy, /*bridge=*/false);
  }
  if (static_cast<double>(sampled_gaps) <
      kMinBridgedShare *
          static_cast<double>(std::max<int64_t>(1, sampled_points))) {
    return;
  }
  for (int v = 0; v < h; ++v) {
    WalkThinGaps(data + static_cast<ptrdiff_t>(v) * w, w, 1, fx, true);
  }
  for (int u = 0; u < w; ++u) WalkThinGaps(data + u, h, w, fy, true);
}

}  // namespace

absl::Status Validate(const NormalOptions& options) {
  if (!(options.baseline_m > 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normals.baseline_m must be > 0, got ", options.baseline_m));
  }
  if (options.smoothing_half_window < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("normals.smoothing_half_window must be >= 0, got ",
                     options.smoothing_half_window));
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
  const float inv_fx = static_cast<float>(1.0 / frame.intrinsics.fx);
  const float inv_fy = static_cast<float>(1.0 / frame.intrinsics.fy);
  const float cx = static_cast<float>(frame.intrinsics.cx);
  const float cy = static_cast<float>(frame.intrinsics.cy);
  // Rows in parallel ranges: each writes its own rows.
  ParallelForRanges(h, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const float* depth = frame.depth.ptr<float>(v);
      cv::Vec3f* out = cloud.xyz.ptr<cv::Vec3f>(v);
      cv::Vec3f* normal = cloud.normals.ptr<cv::Vec3f>(v);
      const float ny = (static_cast<float>(v) - cy) * inv_fy;
      for (int u = 0; u < w; ++u) {
        const float z = depth[u];
        if (std::isnan(z)) {
          out[u] = {kNaN, kNaN, kNaN};
        } else {
          out[u] = {(static_cast<float>(u) - cx) * inv_fx * z, ny * z, z};
        }
        normal[u] = {kNaN, kNaN, kNaN};
      }
    }
  });
  BridgeThinGaps(frame.intrinsics, cloud.xyz);
  return cloud;
}

void EstimateNormals(const NormalOptions& options, OrganizedCloud& cloud) {
  const int w = cloud.width(), h = cloud.height();
  cloud.normals.create(h, w, CV_32FC3);
  const float focal_px =
      static_cast<float>(0.5 * (cloud.intrinsics.fx + cloud.intrinsics.fy));
  const cv::Mat smooth = SmoothValidPoints(
      cloud.xyz,
      static_cast<int>(std::lround(options.smoothing_half_window *
                                   cloud.intrinsics.fx / kReferenceFocalPx)));
  // Rows in parallel: each writes its own row of normals.
  ParallelForRanges(h, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const cv::Vec3f* row = cloud.xyz.ptr<cv::Vec3f>(v);
      cv::Vec3f* out = cloud.normals.ptr<cv::Vec3f>(v);
      for (int u = 0; u < w; ++u) {
        out[u] = {kNaN, kNaN, kNaN};
        const float z = row[u][2];
        if (std::isnan(z)) continue;
        const int r = HalfWindow(options, focal_px, z);
        if (u - r < 0 || u + r >= w || v - r < 0 || v + r >= h) continue;
        // The four samples must lie on the same surface as the centre.
        const float max_change = options.max_depth_change_factor * z * r;
        const float zl = row[u - r][2], zr = row[u + r][2];
        const float zu = cloud.xyz.ptr<cv::Vec3f>(v - r)[u][2];
        const float zd = cloud.xyz.ptr<cv::Vec3f>(v + r)[u][2];
        if (!(std::abs(zl - z) <= max_change &&
              std::abs(zr - z) <= max_change &&
              std::abs(zu - z) <= max_change &&
              std::abs(zd - z) <= max_change)) {
          continue;
        }
        const cv::Vec3f& left = smooth.ptr<cv::Vec3f>(v)[u - r];
        const cv::Vec3f& right = smooth.ptr<cv::Vec3f>(v)[u + r];
        const cv::Vec3f& up = smooth.ptr<cv::Vec3f>(v - r)[u];
        const cv::Vec3f& down = smooth.ptr<cv::Vec3f>(v + r)[u];
        const cv::Vec3f gu = right - left;
        const cv::Vec3f gv = down - up;
        cv::Vec3f n = gv.cross(gu);
        const float norm2 = n.dot(n);
        if (!(norm2 > 0.0f)) continue;  // also false for NaN
        n *= 1.0f / std::sqrt(norm2);
        // Orient towards the camera (the origin): n . p < 0.
        if (n[0] * row[u][0] + n[1] * row[u][1] + n[2] * z > 0.0f) n = -n;
        out[u] = n;
      }
    }
  });
}

absl::StatusOr<OrganizedCloud> BuildOrganizedCloud(
    const RgbdFrame& frame, const NormalOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (frame.depth.empty() || frame.depth.type() != CV_32FC1) {
    return absl::InvalidArgumentError("frame.depth: expected CV_32FC1 metres");
  }
  OrganizedCloud cloud = BackProject(frame);
  EstimateNormals(options, cloud);
  return cloud;
}

}  // namespace fovea
