#include "core/segmentation/edge_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/lab.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Focal length the pixel options are given at (a Kinect v1's).
constexpr double kReferenceFocalPx = 525.0;
// Largest window radius and blur the options accept, pixels.
constexpr int kMaxRadiusPx = 16;
constexpr float kMaxBlurSigmaPx = 10.0f;
// Below any 1 - n_a . n_b of unit normals (rounding included).
constexpr float kNoPair = -1.0f;

// `px` at a 525 px focal length in pixels of a camera with `fx`, >= 1.
int ScaledRadius(int px, double fx) {
  return std::max(1,
                  static_cast<int>(std::lround(px * fx / kReferenceFocalPx)));
}

absl::Status RadiusError(const char* field, int value) {
  return absl::InvalidArgumentError(absl::StrCat(
      "edge_maps.", field, " must be in [1, ", kMaxRadiusPx, "], got ", value));
}

// SC: largest Sobel gradient magnitude over the Lab channels, scaled so a
// step reads its height.
cv::Mat ColorEdges(const cv::Mat& rgb, double fx,
                   const EdgeMapOptions& options) {
  cv::Mat lab;
  RgbToLab(rgb, &lab);
  if (options.color_blur_sigma_px > 0.0f) {
    const double sigma = options.color_blur_sigma_px * fx / kReferenceFocalPx;
    cv::GaussianBlur(lab, lab, cv::Size(0, 0), sigma, sigma,
                     cv::BORDER_REPLICATE);
  }
  // A step of height H reads H * (sum of the derivative kernel's positive
  // taps) * (sum of the smoothing kernel).
  cv::Mat kd, ks;
  cv::getDerivKernels(kd, ks, 1, 0, options.sobel_aperture, false, CV_32F);
  double positive = 0.0;
  for (int i = 0; i < kd.rows * kd.cols; ++i) {
    positive += std::max(0.0f, kd.at<float>(i));
  }
  const float scale = static_cast<float>(1.0 / (positive * cv::sum(ks)[0]));
  cv::Mat gx, gy;
  cv::Sobel(lab, gx, CV_32F, 1, 0, options.sobel_aperture, 1.0, 0.0,
            cv::BORDER_REPLICATE);
  cv::Sobel(lab, gy, CV_32F, 0, 1, options.sobel_aperture, 1.0, 0.0,
            cv::BORDER_REPLICATE);
  cv::Mat out(rgb.size(), CV_32FC1);
  for (int v = 0; v < rgb.rows; ++v) {
    const cv::Vec3f* x = gx.ptr<cv::Vec3f>(v);
    const cv::Vec3f* y = gy.ptr<cv::Vec3f>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < rgb.cols; ++u) {
      float best = 0.0f;
      for (int c = 0; c < 3; ++c) {
        best = std::max(best, x[u][c] * x[u][c] + y[u][c] * y[u][c]);
      }
      o[u] = std::sqrt(best) * scale;
    }
  }
  return out;
}

// SD: Sobel pattern on depth with taps at +-r, over the centre's depth.
cv::Mat DepthEdges(const cv::Mat& xyz, int r) {
  const int h = xyz.rows, w = xyz.cols;
  // Depth padded by r NaN pixels, so every tap is inside.
  cv::Mat z(h + 2 * r, w + 2 * r, CV_32FC1, cv::Scalar(kNaN));
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* p = xyz.ptr<cv::Vec3f>(v);
    float* o = z.ptr<float>(v + r) + r;
    for (int u = 0; u < w; ++u) o[u] = p[u][2];
  }
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    const float* up = z.ptr<float>(v) + r;
    const float* mid = z.ptr<float>(v + r) + r;
    const float* down = z.ptr<float>(v + 2 * r) + r;
    float* o = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const float c = mid[u];
      if (std::isnan(c)) {
        o[u] = kNaN;
        continue;
      }
      // A tap without depth takes the centre's.
      const auto tap = [c](float t) { return std::isnan(t) ? c : t; };
      const float ul = tap(up[u - r]), um = tap(up[u]), ur = tap(up[u + r]);
      const float ml = tap(mid[u - r]), mr = tap(mid[u + r]);
      const float dl = tap(down[u - r]), dm = tap(down[u]),
                  dr = tap(down[u + r]);
      const float gx = (ur + 2.0f * mr + dr) - (ul + 2.0f * ml + dl);
      const float gy = (dl + 2.0f * dm + dr) - (ul + 2.0f * um + ur);
      o[u] = 0.25f * std::sqrt(gx * gx + gy * gy) / c;
    }
  }
  return out;
}

// CE: the largest 1 - n_a . n_b over the pixel pairs (a, b) at -+r along
// the four directions through the pixel, signed by that pair's fold.
cv::Mat CurvatureEdges(const cv::Mat& xyz, const cv::Mat& normals, int r,
                       bool signed_curvature) {
  const int h = xyz.rows, w = xyz.cols;
  // Per pixel the best pair's 1 - n_a . n_b (kNoPair: none yet) and whether
  // its fold is convex; one direction at a time over whole rows.
  cv::Mat best(h, w, CV_32FC1, cv::Scalar(kNoPair));
  cv::Mat convex(h, w, CV_8UC1, cv::Scalar(0));
  // Half of each pair's offset: right, down, down-right, down-left.
  const cv::Point steps[] = {{r, 0}, {0, r}, {r, r}, {-r, r}};
  for (const cv::Point& s : steps) {
    const int u_begin = std::abs(s.x), u_end = w - std::abs(s.x);
    for (int v = s.y; v + s.y < h; ++v) {
      // Pixel a of pixel u is na[u - s.x], pixel b nb[u + s.x].
      const cv::Vec3f* na = normals.ptr<cv::Vec3f>(v - s.y);
      const cv::Vec3f* nb = normals.ptr<cv::Vec3f>(v + s.y);
      const cv::Vec3f* xa = xyz.ptr<cv::Vec3f>(v - s.y);
      const cv::Vec3f* xb = xyz.ptr<cv::Vec3f>(v + s.y);
      float* b = best.ptr<float>(v);
      uint8_t* cvx = convex.ptr<uint8_t>(v);
      for (int u = u_begin; u < u_end; ++u) {
        const int ua = u - s.x, ub = u + s.x;
        // NaN normals make ce NaN, which is never > b[u].
        const float ce = 1.0f - na[ua].dot(nb[ub]);
        if (ce > b[u]) {
          b[u] = ce;
          // Normals diverging along the pair, (n_b - n_a) . (x_b - x_a) > 0:
          // convex; converging: concave.
          cvx[u] =
              signed_curvature && (nb[ub] - na[ua]).dot(xb[ub] - xa[ua]) > 0.0f;
        }
      }
    }
  }
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* n = normals.ptr<cv::Vec3f>(v);
    const float* b = best.ptr<float>(v);
    const uint8_t* cvx = convex.ptr<uint8_t>(v);
    float* o = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      if (std::isnan(n[u][2]) || b[u] == kNoPair) {
        o[u] = kNaN;
      } else {
        const float ce = std::clamp(b[u], 0.0f, 2.0f);
        o[u] = cvx[u] ? -ce : ce;
      }
    }
  }
  return out;
}

}  // namespace

absl::Status Validate(const EdgeMapOptions& options) {
  if (!(options.color_blur_sigma_px >= 0.0f &&
        options.color_blur_sigma_px <= kMaxBlurSigmaPx)) {
    return absl::InvalidArgumentError(
        absl::StrCat("edge_maps.color_blur_sigma_px must be in [0, ",
                     kMaxBlurSigmaPx, "], got ", options.color_blur_sigma_px));
  }
  if (options.sobel_aperture != 3 && options.sobel_aperture != 5 &&
      options.sobel_aperture != 7) {
    return absl::InvalidArgumentError(
        absl::StrCat("edge_maps.sobel_aperture must be 3, 5 or 7, got ",
                     options.sobel_aperture));
  }
  if (options.depth_radius_px < 1 || options.depth_radius_px > kMaxRadiusPx) {
    return RadiusError("depth_radius_px", options.depth_radius_px);
  }
  if (options.curvature_radius_px < 1 ||
      options.curvature_radius_px > kMaxRadiusPx) {
    return RadiusError("curvature_radius_px", options.curvature_radius_px);
  }
  return absl::OkStatus();
}

EdgeMaps ComputeEdgeMaps(const OrganizedCloud& cloud,
                         const EdgeMapOptions& options) {
  FOVEA_CHECK(Validate(options).ok());
  EdgeMaps maps;
  if (cloud.xyz.empty()) return maps;
  FOVEA_CHECK(cloud.xyz.type() == CV_32FC3);
  FOVEA_CHECK(cloud.normals.type() == CV_32FC3 &&
              cloud.normals.size() == cloud.xyz.size());
  FOVEA_CHECK(cloud.color.type() == CV_8UC3 &&
              cloud.color.size() == cloud.xyz.size());
  const double fx = cloud.intrinsics.fx;
  maps.color = ColorEdges(cloud.color, fx, options);
  maps.depth = DepthEdges(cloud.xyz, ScaledRadius(options.depth_radius_px, fx));
  maps.curvature = CurvatureEdges(cloud.xyz, cloud.normals,
                                  ScaledRadius(options.curvature_radius_px, fx),
                                  options.signed_curvature);
  return maps;
}

}  // namespace fovea
