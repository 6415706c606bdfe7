#include "core/saliency/kootstra.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// The 3 x 3 Sobel responds with 8 x the gradient; this scale reports grey
// levels per px.
constexpr double kSobelScale = 1.0 / 8.0;
// Scales smaller than this on either side have no room for pairs.
constexpr int kMinScaleSide = 3;
// Largest allowed radius, px (ours: keeps the weight table small).
constexpr int kMaxRadius = 64;
// A final map whose range is below this fraction of its largest value is
// flat and becomes all zero (ours).
constexpr double kRelativeFlatTolerance = 1e-6;

// A voting pixel: position, unit gradient, log(1 + |g|).
struct Edgel {
  int x, y;
  float ux, uy;
  float log_magnitude;
};

// The strongest-gradient pixels of one scale, sorted by row then column.
std::vector<Edgel> SelectEdgels(const cv::Mat& grey,
                                const KootstraOptions& options) {
  cv::Mat gx, gy;
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3, kSobelScale, 0, cv::BORDER_REPLICATE);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3, kSobelScale, 0, cv::BORDER_REPLICATE);
  std::vector<std::pair<float, Edgel>> candidates;
  for (int y = 0; y < grey.rows; ++y) {
    const float* gx_row = gx.ptr<float>(y);
    const float* gy_row = gy.ptr<float>(y);
    for (int x = 0; x < grey.cols; ++x) {
      const float m = std::hypot(gx_row[x], gy_row[x]);
      if (m < options.min_gradient || m <= 0.0f) continue;
      candidates.push_back(
          {m, Edgel{x, y, gx_row[x] / m, gy_row[x] / m, std::log1p(m)}});
    }
  }
  const size_t keep = std::min(
      candidates.size(), static_cast<size_t>(options.max_points_per_scale));
  std::nth_element(
      candidates.begin(), candidates.begin() + keep, candidates.end(),
      [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Edgel> edgels;
  edgels.reserve(keep);
  for (size_t k = 0; k < keep; ++k) edgels.push_back(candidates[k].second);
  std::sort(edgels.begin(), edgels.end(), [](const Edgel& a, const Edgel& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  return edgels;
}

// Adds value at the midpoint (mx2 / 2, my2 / 2), given as doubled
// coordinates: a half-integer midpoint is shared equally between its two
// (or four) pixels.
void Splat(cv::Mat& acc, int mx2, int my2, float value) {
  const int x0 = mx2 >> 1, y0 = my2 >> 1;
  const int x1 = x0 + (mx2 & 1), y1 = y0 + (my2 & 1);
  const float share =
      value / static_cast<float>(((mx2 & 1) + 1) * ((my2 & 1) + 1));
  acc.at<float>(y0, x0) += share;
  if (x1 != x0) acc.at<float>(y0, x1) += share;
  if (y1 != y0) {
    acc.at<float>(y1, x0) += share;
    if (x1 != x0) acc.at<float>(y1, x1) += share;
  }
}

// Symmetry votes of every pair of edgels within the radius (Kootstra 2008,
// see kootstra.h) at one scale.
cv::Mat VoteSymmetry(const std::vector<Edgel>& edgels, cv::Size size,
                     const KootstraOptions& options) {
  const int r = options.radius_px;
  // Distance weight and 1/d by squared distance (integer on the pixel grid).
  std::vector<float> weight(r * r + 1), inv_distance(r * r + 1);
  for (int d2 = 1; d2 <= r * r; ++d2) {
    const float d = std::sqrt(static_cast<float>(d2));
    weight[d2] = std::exp(-d / (2.0f * options.distance_sigma_px));
    inv_distance[d2] = 1.0f / d;
  }
  cv::Mat acc = cv::Mat::zeros(size, CV_32F);
  const size_t n = edgels.size();
  for (size_t i = 0; i < n; ++i) {
    const Edgel& a = edgels[i];
    for (size_t j = i + 1; j < n; ++j) {
      const Edgel& b = edgels[j];
      const int dy = b.y - a.y;
      if (dy > r) break;
      const int dx = b.x - a.x;
      if (dx > r || dx < -r) continue;
      const int d2 = dx * dx + dy * dy;
      if (d2 > r * r) continue;
      // cos(theta_i - theta_j) and cos(theta_i + theta_j - 2 alpha) from
      // unit vectors: e^{i(theta_i + theta_j)} e^{-2 i alpha}.
      const float cos_diff = a.ux * b.ux + a.uy * b.uy;
      const float lx = dx * inv_distance[d2], ly = dy * inv_distance[d2];
      const float sum_re = a.ux * b.ux - a.uy * b.uy;
      const float sum_im = a.ux * b.uy + a.uy * b.ux;
      const float cos_sum =
          sum_re * (lx * lx - ly * ly) + sum_im * (2.0f * lx * ly);
      const float phase = (1.0f - cos_sum) * (1.0f - cos_diff);
      const float vote = weight[d2] * phase * a.log_magnitude * b.log_magnitude;
      if (vote > 0.0f) Splat(acc, a.x + b.x, a.y + b.y, vote);
    }
  }
  return acc;
}

}  // namespace

absl::Status Validate(const KootstraOptions& options) {
  if (options.min_level < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "kootstra.min_level must be >= 0, got ", options.min_level));
  }
  if (options.num_scales < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "kootstra.num_scales must be >= 1, got ", options.num_scales));
  }
  if (options.min_level + options.num_scales - 1 > kKootstraMaxLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("kootstra.min_level + kootstra.num_scales - 1 must be <= ",
                     kKootstraMaxLevel, ", got ",
                     options.min_level + options.num_scales - 1));
  }
  if (options.radius_px < 1 || options.radius_px > kMaxRadius) {
    return absl::InvalidArgumentError(
        absl::StrCat("kootstra.radius_px must be in [1, ", kMaxRadius,
                     "], got ", options.radius_px));
  }
  if (!(options.distance_sigma_px > 0.0f &&
        std::isfinite(options.distance_sigma_px))) {
    return absl::InvalidArgumentError(
        absl::StrCat("kootstra.distance_sigma_px must be > 0, got ",
                     options.distance_sigma_px));
  }
  if (!(options.min_gradient >= 0.0f && std::isfinite(options.min_gradient))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "kootstra.min_gradient must be >= 0, got ", options.min_gradient));
  }
  if (options.max_points_per_scale < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("kootstra.max_points_per_scale must be >= 2, got ",
                     options.max_points_per_scale));
  }
  if (!(options.smoothing_sigma_px >= 0.0f &&
        std::isfinite(options.smoothing_sigma_px))) {
    return absl::InvalidArgumentError(
        absl::StrCat("kootstra.smoothing_sigma_px must be >= 0, got ",
                     options.smoothing_sigma_px));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeKootstraSaliency(
    const cv::Mat& color, const KootstraOptions& options) {
  FOVEA_RETURN_IF_ERROR(CheckColorImage(color));
  FOVEA_RETURN_IF_ERROR(Validate(options));
  cv::Mat grey8, level;
  cv::cvtColor(color, grey8, cv::COLOR_RGB2GRAY);
  grey8.convertTo(level, CV_32F);
  cv::Mat map = cv::Mat::zeros(color.size(), CV_32F);
  const int last = options.min_level + options.num_scales - 1;
  for (int l = 0; l <= last; ++l) {
    if (l > 0) cv::pyrDown(level, level);
    if (l < options.min_level) continue;
    if (level.cols < kMinScaleSide || level.rows < kMinScaleSide) break;
    cv::Mat votes =
        VoteSymmetry(SelectEdgels(level, options), level.size(), options);
    if (options.smoothing_sigma_px > 0.0f) {
      cv::GaussianBlur(votes, votes, cv::Size(0, 0), options.smoothing_sigma_px,
                       options.smoothing_sigma_px, cv::BORDER_REPLICATE);
    }
    double max_vote = 0.0;
    cv::minMaxLoc(votes, nullptr, &max_vote);
    if (max_vote <= 0.0) continue;
    cv::Mat resized;
    cv::resize(votes * (1.0 / max_vote), resized, color.size(), 0, 0,
               cv::INTER_LINEAR);
    map += resized;
  }
  StretchToUnit(map, kRelativeFlatTolerance);
  return map;
}

}  // namespace fovea
