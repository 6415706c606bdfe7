#include "core/saliency/itti.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// Feature values are intensities in [0, 1] and opponencies in [0, 3]; a map
// whose range is below this is round-off of a uniform input (ours).
constexpr double kFlatTolerance = 1e-5;
// The four Gabor orientations of Itti 1998, sec. II, degrees.
constexpr std::array<double, 4> kOrientationsDeg = {0.0, 45.0, 90.0, 135.0};

using Pyramid = std::vector<cv::Mat>;

// Linear stretch to [0, 1]; a flat map becomes all zero.
cv::Mat StretchToUnitAbsolute(const cv::Mat& map) {
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(map, &lo, &hi);
  if (hi - lo <= kFlatTolerance) return cv::Mat::zeros(map.size(), CV_32F);
  cv::Mat out;
  map.convertTo(out, CV_32F, 1.0 / (hi - lo), -lo / (hi - lo));
  // Round-off of the affine map can leave -1e-18 or 1 + 1e-7.
  cv::min(cv::max(out, 0.0), 1.0, out);
  return out;
}

Pyramid BuildPyramid(const cv::Mat& level0, int depth) {
  Pyramid pyramid{level0};
  for (int l = 1; l <= depth; ++l) {
    cv::Mat next;
    cv::pyrDown(pyramid.back(), next);
    pyramid.push_back(next);
  }
  return pyramid;
}

cv::Mat ResizeTo(const cv::Mat& map, cv::Size size) {
  if (map.size() == size) return map;
  cv::Mat out;
  const bool shrink = size.width < map.cols;
  cv::resize(map, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

// Is (x, y) a local maximum of its 8-neighbourhood? Ties with a neighbour
// earlier in raster order lose, so a plateau counts once.
bool IsLocalMax(const cv::Mat& map, int x, int y) {
  const float v = map.at<float>(y, x);
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= map.cols || ny >= map.rows) continue;
      const float n = map.at<float>(ny, nx);
      const bool earlier = dy < 0 || (dy == 0 && dx < 0);
      if (n > v || (earlier && n == v)) return false;
    }
  }
  return true;
}

// Itti's N(.): [0, 1], times (1 - mean of the other local maxima)^2.
cv::Mat NormalizeItti(const cv::Mat& map, float local_max_threshold) {
  cv::Mat out = StretchToUnitAbsolute(map);
  cv::Point global;
  double global_value = 0.0;
  cv::minMaxLoc(out, nullptr, &global_value, nullptr, &global);
  if (global_value <= 0.0) return out;
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y < out.rows; ++y) {
    const float* row = out.ptr<float>(y);
    for (int x = 0; x < out.cols; ++x) {
      if (row[x] < local_max_threshold || (x == global.x && y == global.y)) {
        continue;
      }
      if (IsLocalMax(out, x, y)) {
        sum += row[x];
        ++count;
      }
    }
  }
  const double mean = count > 0 ? sum / count : 0.0;
  out *= (1.0 - mean) * (1.0 - mean);
  return out;
}

struct ColorPyramids {
  Pyramid intensity, red_green, blue_yellow;
};

// I, R - G and B - Y of Itti 1998, sec. II, each as a pyramid.
ColorPyramids BuildColorPyramids(const cv::Mat& color, int depth,
                                 float color_intensity_threshold) {
  cv::Mat rgb;
  color.convertTo(rgb, CV_32FC3, 1.0 / 255.0);
  cv::Mat ch[3];
  cv::split(rgb, ch);
  cv::Mat intensity = (ch[0] + ch[1] + ch[2]) * (1.0 / 3.0);
  double max_intensity = 0.0;
  cv::minMaxLoc(intensity, nullptr, &max_intensity);
  const float threshold =
      color_intensity_threshold * static_cast<float>(max_intensity);
  cv::Mat rg(color.size(), CV_32F), by(color.size(), CV_32F);
  for (int y = 0; y < color.rows; ++y) {
    const float* i = intensity.ptr<float>(y);
    const cv::Vec3f* p = rgb.ptr<cv::Vec3f>(y);
    float* rg_row = rg.ptr<float>(y);
    float* by_row = by.ptr<float>(y);
    for (int x = 0; x < color.cols; ++x) {
      if (i[x] <= threshold || i[x] <= 0.0f) {
        rg_row[x] = by_row[x] = 0.0f;
        continue;
      }
      const float r = p[x][0] / i[x], g = p[x][1] / i[x], b = p[x][2] / i[x];
      const float red = std::max(0.0f, r - 0.5f * (g + b));
      const float green = std::max(0.0f, g - 0.5f * (r + b));
      const float blue = std::max(0.0f, b - 0.5f * (r + g));
      const float yellow =
          std::max(0.0f, 0.5f * (r + g) - 0.5f * std::abs(r - g) - b);
      rg_row[x] = red - green;
      by_row[x] = blue - yellow;
    }
  }
  return {BuildPyramid(intensity, depth), BuildPyramid(rg, depth),
          BuildPyramid(by, depth)};
}

// Gabor energy (quadrature pair) of the intensity pyramid at one
// orientation, at the levels centre-surround reads (finer ones stay empty);
// the even kernel is made zero-mean so a flat image has 0.
Pyramid GaborPyramid(const Pyramid& intensity, double theta_deg,
                     const IttiOptions& options) {
  const cv::Size ksize(options.gabor_kernel_size, options.gabor_kernel_size);
  const double theta = theta_deg * CV_PI / 180.0;
  cv::Mat even =
      cv::getGaborKernel(ksize, options.gabor_sigma_px, theta,
                         options.gabor_wavelength_px, 1.0, 0.0, CV_32F);
  even -= cv::mean(even)[0];
  const cv::Mat odd =
      cv::getGaborKernel(ksize, options.gabor_sigma_px, theta,
                         options.gabor_wavelength_px, 1.0, CV_PI / 2.0, CV_32F);
  Pyramid out(intensity.size());
  for (size_t l = options.min_center_level; l < intensity.size(); ++l) {
    const cv::Mat& level = intensity[l];
    cv::Mat e, o;
    cv::filter2D(level, e, CV_32F, even, cv::Point(-1, -1), 0,
                 cv::BORDER_REPLICATE);
    cv::filter2D(level, o, CV_32F, odd, cv::Point(-1, -1), 0,
                 cv::BORDER_REPLICATE);
    cv::magnitude(e, o, out[l]);
  }
  return out;
}

// |F(c) - F(s)| with F(s) interpolated to the size of F(c).
cv::Mat CenterSurround(const Pyramid& feature, int c, int s) {
  cv::Mat surround = ResizeTo(feature[s], feature[c].size());
  return cv::abs(feature[c] - surround);
}

// sum over (c, s) of N(CS(feature, c, s)) at map_level (eq. 5-7).
cv::Mat AcrossScaleSum(const Pyramid& feature, const IttiOptions& options,
                       cv::Size map_size) {
  cv::Mat sum = cv::Mat::zeros(map_size, CV_32F);
  for (int c = options.min_center_level; c <= options.max_center_level; ++c) {
    for (int d = options.min_delta; d <= options.max_delta; ++d) {
      const cv::Mat normalized = NormalizeItti(
          CenterSurround(feature, c, c + d), options.local_max_threshold);
      sum += ResizeTo(normalized, map_size);
    }
  }
  return sum;
}

cv::Mat ComputeMasterMap(const cv::Mat& color, const IttiOptions& options) {
  const int depth =
      std::max(options.max_center_level + options.max_delta, options.map_level);
  const ColorPyramids pyr =
      BuildColorPyramids(color, depth, options.color_intensity_threshold);
  const cv::Size map_size = pyr.intensity[options.map_level].size();
  const float t = options.local_max_threshold;

  const cv::Mat intensity = AcrossScaleSum(pyr.intensity, options, map_size);
  const cv::Mat color_sum = AcrossScaleSum(pyr.red_green, options, map_size) +
                            AcrossScaleSum(pyr.blue_yellow, options, map_size);
  cv::Mat orientation = cv::Mat::zeros(map_size, CV_32F);
  for (double theta : kOrientationsDeg) {
    const Pyramid gabor = GaborPyramid(pyr.intensity, theta, options);
    orientation += NormalizeItti(AcrossScaleSum(gabor, options, map_size), t);
  }
  const float weight_sum = options.intensity_weight + options.color_weight +
                           options.orientation_weight;
  cv::Mat master =
      (options.intensity_weight * NormalizeItti(intensity, t) +
       options.color_weight * NormalizeItti(color_sum, t) +
       options.orientation_weight * NormalizeItti(orientation, t)) *
      (1.0f / weight_sum);
  return master;
}

absl::Status CheckFraction(const char* field, float value) {
  if (!(value >= 0.0f && value < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("itti.", field, " must be in [0, 1), got ", value));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status Validate(const IttiOptions& options) {
  if (options.min_center_level < 0 ||
      options.max_center_level < options.min_center_level) {
    return absl::InvalidArgumentError(absl::StrCat(
        "itti.min_center_level/max_center_level must satisfy 0 <= min <= "
        "max, got ",
        options.min_center_level, "..", options.max_center_level));
  }
  if (options.min_delta < 1 || options.max_delta < options.min_delta) {
    return absl::InvalidArgumentError(absl::StrCat(
        "itti.min_delta/max_delta must satisfy 1 <= min <= max, got ",
        options.min_delta, "..", options.max_delta));
  }
  if (options.max_center_level + options.max_delta > kIttiMaxPyramidLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("itti.max_center_level + itti.max_delta must be <= ",
                     kIttiMaxPyramidLevel, ", got ",
                     options.max_center_level + options.max_delta));
  }
  if (options.map_level < 0 || options.map_level > kIttiMaxPyramidLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("itti.map_level must be in [0, ", kIttiMaxPyramidLevel,
                     "], got ", options.map_level));
  }
  if (!(options.gabor_wavelength_px >= 2.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("itti.gabor_wavelength_px must be >= 2, got ",
                     options.gabor_wavelength_px));
  }
  if (!(options.gabor_sigma_px > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "itti.gabor_sigma_px must be > 0, got ", options.gabor_sigma_px));
  }
  FOVEA_RETURN_IF_ERROR(
      CheckGaborKernelSize("itti", options.gabor_kernel_size));
  FOVEA_RETURN_IF_ERROR(CheckFraction("color_intensity_threshold",
                                      options.color_intensity_threshold));
  FOVEA_RETURN_IF_ERROR(
      CheckFraction("local_max_threshold", options.local_max_threshold));
  return CheckFeatureWeights("itti", options.intensity_weight,
                             options.color_weight, options.orientation_weight);
}

absl::StatusOr<cv::Mat> ComputeIttiSaliency(const cv::Mat& color,
                                            const IttiOptions& options) {
  FOVEA_RETURN_IF_ERROR(CheckColorImage(color));
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const cv::Mat master = ComputeMasterMap(color, options);
  cv::Mat map;
  cv::resize(master, map, color.size(), 0, 0, cv::INTER_LINEAR);
  return StretchToUnitAbsolute(map);
}

}  // namespace fovea
