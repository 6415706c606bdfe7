#include "core/frame/dropout_fill.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

bool Missing(float z) { return !(z > 0.0f); }  // NaN or not positive

// Least-squares plane z = a u + b v + c through the window's points
// (u, v relative to its centre). False when the points span no plane.
struct WindowPlane {
  double a = 0.0, b = 0.0, c = 0.0;
};

bool FitPlane(const std::vector<cv::Vec3f>& points, WindowPlane& plane) {
  double suu = 0, suv = 0, svv = 0, su = 0, sv = 0, n = 0;
  double suz = 0, svz = 0, sz = 0;
  for (const cv::Vec3f& p : points) {
    suu += p[0] * p[0];
    suv += p[0] * p[1];
    svv += p[1] * p[1];
    su += p[0];
    sv += p[1];
    n += 1.0;
    suz += p[0] * p[2];
    svz += p[1] * p[2];
    sz += p[2];
  }
  const cv::Matx33d a(suu, suv, su, suv, svv, sv, su, sv, n);
  const cv::Vec3d rhs(suz, svz, sz);
  cv::Vec3d x;
  if (!cv::solve(a, rhs, x, cv::DECOMP_CHOLESKY)) return false;
  plane = {x[0], x[1], x[2]};
  return true;
}

}  // namespace

absl::Status Validate(const DropoutFillOptions& options) {
  if (options.half_window < 1 || options.half_window > 8) {
    return absl::InvalidArgumentError(
        absl::StrCat("dropout_fill.half_window must be in [1, 8], got ",
                     options.half_window));
  }
  for (const auto& [name, value] :
       {std::pair{"min_valid_fraction", options.min_valid_fraction},
        std::pair{"min_missing_fraction", options.min_missing_fraction},
        std::pair{"min_transition_fraction", options.min_transition_fraction},
        std::pair{"max_outlier_fraction", options.max_outlier_fraction}}) {
    if (!(value >= 0.0f && value <= 1.0f)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "dropout_fill.", name, " must be in [0, 1], got ", value));
    }
  }
  if (options.max_luma < 0 || options.max_luma > 255) {
    return absl::InvalidArgumentError(absl::StrCat(
        "dropout_fill.max_luma must be in [0, 255], got ", options.max_luma));
  }
  if (options.fits_per_interrupt_check < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "dropout_fill.fits_per_interrupt_check must be at least 1, got ",
        options.fits_per_interrupt_check));
  }
  if (options.passes < 1 || options.passes > 8) {
    return absl::InvalidArgumentError(absl::StrCat(
        "dropout_fill.passes must be in [1, 8], got ", options.passes));
  }
  if (options.min_quadrant_points < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("dropout_fill.min_quadrant_points must be >= 1, got ",
                     options.min_quadrant_points));
  }
  if (!(options.max_residual_sigmas > 0.0f) || !(options.min_sigma_m >= 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "dropout_fill.max_residual_sigmas must be > 0 and min_sigma_m >= 0, "
        "got ",
        options.max_residual_sigmas, " and ", options.min_sigma_m));
  }
  return absl::OkStatus();
}

namespace {

// 1 where `depth` has a value, and its integral image.
cv::Mat ValidSums(const cv::Mat& depth, cv::Mat& valid) {
  valid.create(depth.size(), CV_8UC1);
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    uint8_t* out = valid.ptr<uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) out[u] = Missing(z[u]) ? 0 : 1;
  }
  cv::Mat sums;
  cv::integral(valid, sums, CV_32S);
  return sums;
}

// Sum over the inclusive box [u0, u1] x [v0, v1] of an integral image.
int BoxSum(const cv::Mat& s, int u0, int v0, int u1, int v1) {
  if (u1 < u0 || v1 < v0) return 0;
  return s.at<int>(v1 + 1, u1 + 1) - s.at<int>(v0, u1 + 1) -
         s.at<int>(v1 + 1, u0) + s.at<int>(v0, u0);
}

// The depth at (u, v) of the plane through the window's pixels with depth
// in `source`, when they surround it (each quadrant) and lie on one plane
// within the noise; NaN otherwise. `sums`: ValidSums of `source`.
float PlaneDepth(const DropoutFillOptions& options, const SensorModel& sensor,
                 const cv::Mat& source, const cv::Mat& sums, int u, int v,
                 std::vector<cv::Vec3f>& points) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int r = options.half_window;
  const int u0 = std::max(0, u - r), u1 = std::min(source.cols - 1, u + r);
  const int v0 = std::max(0, v - r), v1 = std::min(source.rows - 1, v + r);
  const int q = options.min_quadrant_points;
  if (BoxSum(sums, u0, v0, u, v) < q || BoxSum(sums, u, v0, u1, v) < q ||
      BoxSum(sums, u0, v, u, v1) < q || BoxSum(sums, u, v, u1, v1) < q) {
    return nan;
  }
  points.clear();
  for (int y = v0; y <= v1; ++y) {
    const float* z = source.ptr<float>(y);
    for (int x = u0; x <= u1; ++x) {
      if (!Missing(z[x])) {
        points.emplace_back(static_cast<float>(x - u),
                            static_cast<float>(y - v), z[x]);
      }
    }
  }
  WindowPlane plane;
  if (!FitPlane(points, plane) || !(plane.c > 0.0)) return nan;
  const double tolerance =
      options.max_residual_sigmas *
      std::max<double>(options.min_sigma_m,
                       sensor.DepthSigma(static_cast<float>(plane.c)));
  const auto outliers =
      std::count_if(points.begin(), points.end(), [&](const cv::Vec3f& p) {
        return std::abs(plane.a * p[0] + plane.b * p[1] + plane.c - p[2]) >
               tolerance;
      });
  const bool one_surface = outliers <= options.max_outlier_fraction *
                                           static_cast<double>(points.size());
  return one_surface ? static_cast<float>(plane.c) : nan;
}

}  // namespace

absl::StatusOr<FilledDepth> FillSpeckledDropout(
    const DropoutFillOptions& options, const SensorModel& sensor,
    const cv::Mat& color, const cv::Mat& depth,
    const InterruptCheck& interrupt) {
  CV_Assert(depth.type() == CV_32FC1);
  CV_Assert(color.type() == CV_8UC3 && color.size() == depth.size());
  FilledDepth out;
  out.depth = depth;  // shared until something is filled
  out.filled = cv::Mat::zeros(depth.size(), CV_8UC1);
  if (depth.empty()) return out;
  cv::Mat luma;
  cv::cvtColor(color, luma, cv::COLOR_RGB2GRAY);
  const cv::Mat dark = luma <= options.max_luma;
  cv::Mat valid;
  cv::Mat sums = ValidSums(depth, valid);
  // Most frames have no dark pixel without depth: nothing to do.
  if (cv::countNonZero(dark & (valid == 0)) == 0) return out;
  // The pixels a pass fills, written after it, so that each pass reads the
  // depth as it was before it.
  std::vector<std::pair<cv::Point, float>> fills;
  const auto apply = [&](cv::Mat& reach) {
    if (!fills.empty() && out.depth.data == depth.data) {
      out.depth = depth.clone();
    }
    reach = cv::Mat::zeros(depth.size(), CV_8UC1);
    for (const auto& [p, z] : fills) {
      out.depth.at<float>(p) = z;
      reach.at<uint8_t>(p) = 255;
    }
    out.filled |= reach;
    out.filled_pixels += static_cast<int>(fills.size());
    fills.clear();
  };
  // Counts the plane fits, asking the interrupt after every
  // fits_per_interrupt_check of them.
  int fits = 0;
  const int every = std::max(1, options.fits_per_interrupt_check);
  const auto fitted = [&]() {
    return ++fits % every == 0 ? CheckInterrupt(interrupt) : absl::OkStatus();
  };
  // Pass 1, speckle: windows by integral images of the pixels with depth
  // and of where depth starts or stops, to the right (across) and below
  // (down). Most missing pixels (the background, shadows) are rejected by
  // these counts alone.
  const int r = options.half_window;
  cv::Mat across = cv::Mat::zeros(depth.size(), CV_8UC1);
  cv::Mat down = cv::Mat::zeros(depth.size(), CV_8UC1);
  for (int v = 0; v < depth.rows; ++v) {
    const uint8_t* row = valid.ptr<uint8_t>(v);
    const uint8_t* next = v + 1 < depth.rows ? valid.ptr<uint8_t>(v + 1) : row;
    uint8_t* a = across.ptr<uint8_t>(v);
    uint8_t* d = down.ptr<uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (u + 1 < depth.cols) a[u] = row[u] != row[u + 1];
      d[u] = row[u] != next[u];
    }
  }
  cv::Mat across_sums, down_sums;
  cv::integral(across, across_sums, CV_32S);
  cv::integral(down, down_sums, CV_32S);
  std::vector<cv::Vec3f> points;
  for (int v = 0; v < depth.rows; ++v) {
    const uint8_t* has = valid.ptr<uint8_t>(v);
    const uint8_t* is_dark = dark.ptr<uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (has[u] || !is_dark[u]) continue;
      const int u0 = std::max(0, u - r), u1 = std::min(depth.cols - 1, u + r);
      const int v0 = std::max(0, v - r), v1 = std::min(depth.rows - 1, v + r);
      const int area = (u1 - u0 + 1) * (v1 - v0 + 1);
      const int n = BoxSum(sums, u0, v0, u1, v1);
      if (n < options.min_valid_fraction * area ||
          area - n < options.min_missing_fraction * area) {
        continue;
      }
      const int pairs = (u1 - u0) * (v1 - v0 + 1) + (u1 - u0 + 1) * (v1 - v0);
      const int transitions = BoxSum(across_sums, u0, v0, u1 - 1, v1) +
                              BoxSum(down_sums, u0, v0, u1, v1 - 1);
      if (transitions < options.min_transition_fraction * pairs) continue;
      FOVEA_RETURN_IF_ERROR(fitted());
      const float z = PlaneDepth(options, sensor, depth, sums, u, v, points);
      if (!std::isnan(z)) fills.emplace_back(cv::Point(u, v), z);
    }
  }
  cv::Mat reach;
  apply(reach);
  // Later passes: the pixels left missing within the window of one the
  // pass before filled, from the measured and filled depth, the same plane
  // test without the speckle test (they are what the first pass left
  // between its pixels, at the speckle's edge and in its larger gaps).
  const cv::Mat box = cv::Mat::ones(2 * r + 1, 2 * r + 1, CV_8UC1);
  for (int pass = 1; pass < options.passes && cv::countNonZero(reach) > 0;
       ++pass) {
    cv::dilate(reach, reach, box);
    reach &= dark;
    sums = ValidSums(out.depth, valid);
    for (int v = 0; v < depth.rows; ++v) {
      const uint8_t* has = valid.ptr<uint8_t>(v);
      const uint8_t* near = reach.ptr<uint8_t>(v);
      for (int u = 0; u < depth.cols; ++u) {
        if (has[u] || !near[u]) continue;
        FOVEA_RETURN_IF_ERROR(fitted());
        const float z =
            PlaneDepth(options, sensor, out.depth, sums, u, v, points);
        if (!std::isnan(z)) fills.emplace_back(cv::Point(u, v), z);
      }
    }
    apply(reach);
  }
  return out;
}

}  // namespace fovea
