#ifndef FOVEA_CORE_SALIENCY_KOOTSTRA_H_
#define FOVEA_CORE_SALIENCY_KOOTSTRA_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

struct KootstraOptions {
  // Pyramid level of the finest scale, 0 = the input (ours: 1, half
  // resolution, keeps 640 x 480 fast; with radius_px 24 the scales see
  // objects up to ~100, 200, 400 px across).
  int min_level = 1;
  // Number of scales, levels min_level .. min_level + num_scales - 1
  // (Kootstra et al. 2008 sum several octaves; 3 cover the objects of a
  // 640 x 480 table scene), >= 1,
  // min_level + num_scales - 1 <= kKootstraMaxLevel.
  int num_scales = 3;
  // Pairs of pixels at most this far apart vote, px at each scale, (0, 64]
  // (Kootstra et al. 2008: r = 24).
  int radius_px = 24;
  // Sigma of Reisfeld's distance weight D = exp(-|p_i - p_j| / (2 sigma)),
  // px at each scale, > 0 (Reisfeld et al. 1995; ours: r / 2, so a
  // pair at the radius weighs 1/e of a close one).
  float distance_sigma_px = 12.0f;
  // Pixels whose gradient magnitude is below this take no part, grey levels
  // (0..255) per px, >= 0 (ours: below sensor noise on smooth surfaces).
  float min_gradient = 4.0f;
  // At most this many strongest-gradient pixels per scale take part, >= 2
  // (ours: bounds the pairs per scale to max_points^2 / 2).
  int max_points_per_scale = 2000;
  // Sigma of the Gaussian that spreads each scale's midpoint votes, px at
  // that scale, >= 0 (ours).
  float smoothing_sigma_px = 1.5f;
};

// Deepest pyramid level KootstraOptions may reach (ours).
inline constexpr int kKootstraMaxLevel = 8;

absl::Status Validate(const KootstraOptions& options);

// Radial 2D symmetry (Kootstra, Nederveen & de Boer, "Paying Attention to
// Symmetry", BMVC 2008, after Reisfeld, Wolfson & Yeshurun 1995). At each
// scale (a level of the grey image's Gaussian pyramid) the pixels with the
// strongest Sobel gradients g, at angle theta, vote in pairs (i, j) at most
// radius_px apart, at their midpoint p = (p_i + p_j) / 2:
//   c(i,j) = D(i,j) P(i,j) log(1 + |g_i|) log(1 + |g_j|)
//   D(i,j) = exp(-|p_i - p_j| / (2 sigma))       (Reisfeld 1995)
//   P(i,j) = (1 - cos(theta_i + theta_j - 2 alpha_ij))
//            (1 - cos(theta_i - theta_j))       (Kootstra 2008)
// alpha_ij the angle of the line from p_i to p_j, |g| in grey levels per px.
// P is largest (4) for two gradients that mirror each other across the
// pair's bisector and point in opposite directions, as on either side of a
// filled disc; gradients along one edge get P = 0. Votes are splatted
// bilinearly, each scale's map blurred, scaled to a maximum of 1, resized
// bilinearly to the input, and the scales summed; the sum is linearly
// stretched to [0, 1].
//
// In: color, CV_8UC3 RGB, any size >= 1 x 1 (scales smaller than 3 x 3 px
// are skipped).
// Out: CV_32FC1 of color's size in [0, 1]; an image without gradients
// above min_gradient (a uniform one) gives an all-zero map.
// Errors: INVALID_ARGUMENT "color: empty" or "color: ... CV_8UC3" for bad
// input, the options field name for bad options.
absl::StatusOr<cv::Mat> ComputeKootstraSaliency(const cv::Mat& color,
                                                const KootstraOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_KOOTSTRA_H_
