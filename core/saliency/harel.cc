#include "core/saliency/harel.h"

#include <Eigen/Core>
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

// A feature map whose range on the grid is below this (feature units, all
// in [0, 1]) has no contrast: round-off of a uniform input (ours).
constexpr float kMinContrast = 1e-4f;
// Colour opponency is 0 where max(r, g, b) is below this: the ratio is noise
// in the dark (ours, after Itti 1998's 1/10 rule for r, g, b / I).
constexpr float kDarkThreshold = 0.1f;
// The four Gabor orientations, degrees (as Itti 1998 and the GBVS code).
constexpr std::array<double, 4> kOrientationsDeg = {0.0, 45.0, 90.0, 135.0};
// A final map whose range is below this fraction of its largest value is
// flat and becomes all zero (ours).
constexpr double kRelativeFlatTolerance = 1e-4;

cv::Size GridSize(cv::Size image, int long_side) {
  const int image_long = std::max(image.width, image.height);
  const int image_short = std::min(image.width, image.height);
  const int short_side =
      std::max(2, static_cast<int>(std::lround(static_cast<double>(long_side) *
                                               image_short / image_long)));
  return image.width >= image.height ? cv::Size(long_side, short_side)
                                     : cv::Size(short_side, long_side);
}

cv::Mat ResizeTo(const cv::Mat& map, cv::Size size) {
  cv::Mat out;
  const bool shrink = size.area() < map.size().area();
  cv::resize(map, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

struct FeatureMaps {
  // channel -> feature maps of that channel on the grid.
  std::vector<cv::Mat> intensity, color, orientation;
};

// Colour opponency of GBVS: |r - g| and |b - min(r, g)| over max(r, g, b).
void ColorOpponency(const cv::Mat& rgb, cv::Mat& rg, cv::Mat& by) {
  rg.create(rgb.size(), CV_32F);
  by.create(rgb.size(), CV_32F);
  for (int y = 0; y < rgb.rows; ++y) {
    const cv::Vec3f* p = rgb.ptr<cv::Vec3f>(y);
    float* rg_row = rg.ptr<float>(y);
    float* by_row = by.ptr<float>(y);
    for (int x = 0; x < rgb.cols; ++x) {
      const float r = p[x][0], g = p[x][1], b = p[x][2];
      const float top = std::max({r, g, b});
      if (top < kDarkThreshold) {
        rg_row[x] = by_row[x] = 0.0f;
        continue;
      }
      rg_row[x] = std::abs(r - g) / top;
      by_row[x] = std::abs(b - std::min(r, g)) / top;
    }
  }
}

cv::Mat GaborEnergy(const cv::Mat& intensity, double theta_deg,
                    const HarelOptions& options) {
  const cv::Size ksize(options.gabor_kernel_size, options.gabor_kernel_size);
  const double theta = theta_deg * CV_PI / 180.0;
  cv::Mat even =
      cv::getGaborKernel(ksize, options.gabor_sigma_px, theta,
                         options.gabor_wavelength_px, 1.0, 0.0, CV_32F);
  even -= cv::mean(even)[0];
  const cv::Mat odd =
      cv::getGaborKernel(ksize, options.gabor_sigma_px, theta,
                         options.gabor_wavelength_px, 1.0, CV_PI / 2.0, CV_32F);
  cv::Mat e, o, energy;
  cv::filter2D(intensity, e, CV_32F, even, cv::Point(-1, -1), 0,
               cv::BORDER_REPLICATE);
  cv::filter2D(intensity, o, CV_32F, odd, cv::Point(-1, -1), 0,
               cv::BORDER_REPLICATE);
  cv::magnitude(e, o, energy);
  return energy;
}

FeatureMaps ComputeFeatureMaps(const cv::Mat& color, cv::Size grid,
                               const HarelOptions& options) {
  cv::Mat level;
  color.convertTo(level, CV_32FC3, 1.0 / 255.0);
  FeatureMaps maps;
  for (int l = 0; l <= options.max_feature_level; ++l) {
    if (l > 0) cv::pyrDown(level, level);
    if (l < options.min_feature_level) continue;
    cv::Mat ch[3];
    cv::split(level, ch);
    const cv::Mat intensity = (ch[0] + ch[1] + ch[2]) * (1.0 / 3.0);
    cv::Mat rg, by;
    ColorOpponency(level, rg, by);
    maps.intensity.push_back(ResizeTo(intensity, grid));
    maps.color.push_back(ResizeTo(rg, grid));
    maps.color.push_back(ResizeTo(by, grid));
    for (double theta : kOrientationsDeg) {
      maps.orientation.push_back(
          ResizeTo(GaborEnergy(intensity, theta, options), grid));
    }
  }
  return maps;
}

// F(i, j) = exp(-|i - j|^2 / (2 sigma^2)) over the grid's cells, row-major.
Eigen::MatrixXf DistanceGaussian(cv::Size grid, float sigma) {
  const int n = grid.area();
  Eigen::MatrixXf f(n, n);
  const float inv = 1.0f / (2.0f * sigma * sigma);
  for (int j = 0; j < n; ++j) {
    const int xj = j % grid.width, yj = j / grid.width;
    for (int i = 0; i < n; ++i) {
      const int dx = i % grid.width - xj, dy = i / grid.width - yj;
      f(i, j) = std::exp(-static_cast<float>(dx * dx + dy * dy) * inv);
    }
  }
  return f;
}

// F v for F(i, j) = exp(-|i - j|^2 / (2 sigma^2)) on the grid (cells
// row-major), without forming F: F is separable, exp(-dx^2 / 2s^2) *
// exp(-dy^2 / 2s^2), so it is a row pass then a column pass, O(n (w + h)).
Eigen::VectorXf GaussianTimes(const Eigen::VectorXf& v, cv::Size grid,
                              float sigma) {
  const int w = grid.width, h = grid.height;
  const int reach = std::max(w, h);
  std::vector<float> g(reach);
  for (int k = 0; k < reach; ++k) {
    g[k] = std::exp(-static_cast<float>(k * k) / (2.0f * sigma * sigma));
  }
  Eigen::VectorXf rows = Eigen::VectorXf::Zero(v.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int x2 = 0; x2 < w; ++x2) sum += g[std::abs(x - x2)] * v(y * w + x2);
      rows(y * w + x) = sum;
    }
  }
  Eigen::VectorXf out = Eigen::VectorXf::Zero(v.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int y2 = 0; y2 < h; ++y2)
        sum += g[std::abs(y - y2)] * rows(y2 * w + x);
      out(y * w + x) = sum;
    }
  }
  return out;
}

// The equilibrium of the chain with P(i -> j) = w(i, j) / out(i), out the
// out-weights sum_j w(i, j) (a node without out-weight keeps its mass), by
// power iteration from start: at most max_iterations steps, until the L1
// change is below tolerance. w is given by transposed_times(v) = w^T v.
template <typename TransposedTimes>
Eigen::VectorXf Equilibrium(const Eigen::VectorXf& out,
                            TransposedTimes transposed_times,
                            Eigen::VectorXf pi, const HarelOptions& options) {
  pi /= pi.sum();
  Eigen::VectorXf scaled(pi.size());
  for (int it = 0; it < options.max_iterations; ++it) {
    for (int i = 0; i < pi.size(); ++i) {
      scaled(i) = out(i) > 0.0f ? pi(i) / out(i) : 0.0f;
    }
    Eigen::VectorXf next = transposed_times(scaled);
    for (int i = 0; i < pi.size(); ++i) {
      if (out(i) <= 0.0f) next(i) += pi(i);
    }
    next /= next.sum();
    const float change = (next - pi).lpNorm<1>();
    pi = next;
    if (change < options.tolerance) break;
  }
  return pi;
}

// Where the power iteration starts: the detailed-balance solution
// node_factor(i) * out(i), or the uniform distribution (see warm_start).
Eigen::VectorXf StartingPoint(const Eigen::VectorXf& out,
                              const Eigen::VectorXf& node_factor,
                              const HarelOptions& options) {
  if (!options.warm_start) return Eigen::VectorXf::Ones(out.size());
  return node_factor.cwiseProduct(out);
}

// Activation then normalisation of one feature map (see harel.h); the
// result sums to 1, or is all zero for a map without contrast. f_act is
// the (symmetric) distance Gaussian of the activation chain.
Eigen::VectorXf ActivateAndNormalize(const cv::Mat& feature,
                                     const Eigen::MatrixXf& f_act,
                                     cv::Size grid, float norm_sigma,
                                     const HarelOptions& options) {
  const int n = static_cast<int>(feature.total());
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(feature, &lo, &hi);
  if (hi - lo < kMinContrast) return Eigen::VectorXf::Zero(n);
  const cv::Mat contiguous = feature.isContinuous() ? feature : feature.clone();
  // M / max M + floor: the floor is a fraction of the map's peak.
  const float inv_max = 1.0f / static_cast<float>(hi);
  Eigen::VectorXf log_m(n);
  for (int i = 0; i < n; ++i) {
    log_m(i) = std::log(std::max(0.0f, contiguous.ptr<float>()[i]) * inv_max +
                        options.log_floor);
  }
  // Activation: w(i, j) = |log M(i) - log M(j)| F_act(i, j), symmetric, so
  // the out-weights are the column sums and w^T v = w v.
  Eigen::MatrixXf w(n, n);
  Eigen::VectorXf out(n);
  for (int j = 0; j < n; ++j) {
    w.col(j) = (log_m.array() - log_m(j)).abs() * f_act.col(j).array();
    out(j) = w.col(j).sum();
  }
  const Eigen::VectorXf activation = Equilibrium(
      out,
      [&](const Eigen::VectorXf& v) -> Eigen::VectorXf {
        return w.transpose() * v;
      },
      StartingPoint(out, Eigen::VectorXf::Ones(n), options), options);
  // Normalisation: w(i, j) = F_norm(i, j) A(j), never formed: out = F A and
  // (w^T v)(j) = A(j) (F v)(j), F symmetric.
  const Eigen::VectorXf norm_out = GaussianTimes(activation, grid, norm_sigma);
  return Equilibrium(
      norm_out,
      [&](const Eigen::VectorXf& v) -> Eigen::VectorXf {
        return activation.cwiseProduct(GaussianTimes(v, grid, norm_sigma));
      },
      StartingPoint(norm_out, activation, options), options);
}

cv::Mat ComputeGridMap(const cv::Mat& color, const HarelOptions& options) {
  const cv::Size grid = GridSize(color.size(), options.grid_long_side);
  const FeatureMaps maps = ComputeFeatureMaps(color, grid, options);
  const float long_side = static_cast<float>(options.grid_long_side);
  const Eigen::MatrixXf f_act =
      DistanceGaussian(grid, options.activation_sigma_fraction * long_side);
  const float norm_sigma = options.normalization_sigma_fraction * long_side;
  const int n = grid.area();
  auto channel_mean = [&](const std::vector<cv::Mat>& channel) {
    Eigen::VectorXf sum = Eigen::VectorXf::Zero(n);
    for (const cv::Mat& m : channel) {
      sum += ActivateAndNormalize(m, f_act, grid, norm_sigma, options);
    }
    return Eigen::VectorXf(sum / static_cast<float>(channel.size()));
  };
  const Eigen::VectorXf master =
      options.intensity_weight * channel_mean(maps.intensity) +
      options.color_weight * channel_mean(maps.color) +
      options.orientation_weight * channel_mean(maps.orientation);
  cv::Mat out(grid, CV_32F);
  for (int i = 0; i < n; ++i) out.ptr<float>()[i] = master(i);
  return out;
}

absl::Status CheckPositiveFinite(const char* field, double value) {
  if (!(value > 0.0 && std::isfinite(value))) {
    return absl::InvalidArgumentError(
        absl::StrCat("harel.", field, " must be > 0, got ", value));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status Validate(const HarelOptions& options) {
  if (options.grid_long_side < 2 ||
      options.grid_long_side > kHarelMaxGridSide) {
    return absl::InvalidArgumentError(
        absl::StrCat("harel.grid_long_side must be in [2, ", kHarelMaxGridSide,
                     "], got ", options.grid_long_side));
  }
  if (options.min_feature_level < 0 ||
      options.max_feature_level < options.min_feature_level ||
      options.max_feature_level > 10) {
    return absl::InvalidArgumentError(absl::StrCat(
        "harel.min_feature_level/max_feature_level must satisfy 0 <= min <= "
        "max <= 10, got ",
        options.min_feature_level, "..", options.max_feature_level));
  }
  const std::pair<const char*, double> positive[] = {
      {"activation_sigma_fraction", options.activation_sigma_fraction},
      {"normalization_sigma_fraction", options.normalization_sigma_fraction},
      {"log_floor", options.log_floor},
      {"tolerance", options.tolerance},
      {"gabor_sigma_px", options.gabor_sigma_px},
  };
  for (const auto& [field, value] : positive) {
    FOVEA_RETURN_IF_ERROR(CheckPositiveFinite(field, value));
  }
  if (options.max_iterations < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "harel.max_iterations must be >= 1, got ", options.max_iterations));
  }
  if (!(options.blur_fraction >= 0.0f && options.blur_fraction <= 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "harel.blur_fraction must be in [0, 1], got ", options.blur_fraction));
  }
  if (!(options.gabor_wavelength_px >= 2.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("harel.gabor_wavelength_px must be >= 2, got ",
                     options.gabor_wavelength_px));
  }
  FOVEA_RETURN_IF_ERROR(
      CheckGaborKernelSize("harel", options.gabor_kernel_size));
  return CheckFeatureWeights("harel", options.intensity_weight,
                             options.color_weight, options.orientation_weight);
}

absl::StatusOr<cv::Mat> ComputeHarelSaliency(const cv::Mat& color,
                                             const HarelOptions& options) {
  FOVEA_RETURN_IF_ERROR(CheckColorImage(color));
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const cv::Mat grid_map = ComputeGridMap(color, options);
  cv::Mat map;
  cv::resize(grid_map, map, color.size(), 0, 0, cv::INTER_LINEAR);
  const double sigma = options.blur_fraction * std::max(color.cols, color.rows);
  if (sigma > 0.0) {
    cv::GaussianBlur(map, map, cv::Size(0, 0), sigma, sigma,
                     cv::BORDER_REPLICATE);
  }
  StretchToUnit(map, kRelativeFlatTolerance);
  return map;
}

}  // namespace fovea
