#ifndef FOVEA_CORE_SALIENCY_HAREL_H_
#define FOVEA_CORE_SALIENCY_HAREL_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

struct HarelOptions {
  // Cells on the long side of the coarse grid the chains live on; the short
  // side keeps the aspect ratio, >= 2 cells (GBVS code, salmapmaxsize: 32,
  // so 32 x 24 for 640 x 480). At most kHarelMaxGridSide.
  int grid_long_side = 32;
  // Pyramid levels the feature maps are taken at, min..max, 0 = input
  // (GBVS code, params.levels: 2..4).
  int min_feature_level = 2;
  int max_feature_level = 4;
  // Sigma of the distance Gaussian F of the activation chain, as a fraction
  // of the grid's long side (GBVS code, sigma_frac_act: 0.15).
  float activation_sigma_fraction = 0.15f;
  // The same for the normalisation chain (GBVS code, sigma_frac_norm: 0.06).
  float normalization_sigma_fraction = 0.06f;
  // The dissimilarity |log(M(i)/M(j))| is taken of M / max M + log_floor,
  // > 0, so that a zero feature is finite (ours). 0.05: a faint response
  // (the ends of a horizontal bar in a vertical-orientation map) is then
  // not nearly as dissimilar from empty background as a strong one; with
  // 1e-3 every faint response counts and orientation pop-out is lost.
  float log_floor = 0.05f;
  // Power iteration: at most this many steps, stopping once the L1 change
  // of the distribution is below tolerance (GBVS code, tol: 1e-4).
  int max_iterations = 1000;
  float tolerance = 1e-4f;
  // Start the power iteration at the detailed-balance solution. Both chains
  // are reversible (the activation weights are symmetric; the normalisation
  // weights A(j) F(i,j) satisfy A(i) w(i,j) = A(j) w(j,i)), so their
  // equilibria are pi(i) ~ sum_j w(i,j) and pi(i) ~ A(i) sum_j w(i,j)
  // exactly and the iteration stops after one step. false starts from the
  // uniform distribution, as the GBVS code does (same answer, slower).
  bool warm_start = true;
  // Sigma of the final blur, as a fraction of the output's long side (GBVS
  // code, blurfrac: 0.02), >= 0.
  float blur_fraction = 0.02f;
  // Gabor filter for the orientation channel, px of the pyramid level:
  // wavelength, envelope sigma, odd kernel side (SaliencyToolbox: 7, 2.33, 9).
  double gabor_wavelength_px = 7.0;
  double gabor_sigma_px = 2.33;
  int gabor_kernel_size = 9;
  // Weights of the intensity, colour and orientation channels, >= 0 with a
  // positive sum (GBVS code: equal).
  float intensity_weight = 1.0f;
  float color_weight = 1.0f;
  float orientation_weight = 1.0f;
};

// Largest grid side (ours: the chains are dense, memory grows as side^4).
inline constexpr int kHarelMaxGridSide = 64;

absl::Status Validate(const HarelOptions& options);

// Graph-based visual saliency (Harel, Koch & Perona, "Graph-Based Visual
// Saliency", NIPS 2006). Feature maps M on a grid of n cells, each
// resized from levels min..max_feature_level of a Gaussian pyramid:
// intensity (r + g + b)/3; colour |r - g| / max(r,g,b) and
// |b - min(r,g)| / max(r,g,b) (GBVS code, after Walther); orientation, the
// Gabor energy of intensity at 0, 45, 90, 135 deg. For each map:
//   activation: the equilibrium A of the Markov chain with edge weights
//     w(i,j) = |log(M(i)/M(j))| F_act(i,j),  F(i,j) = exp(-|i-j|^2 / 2s^2)
//     (|i - j| the grid distance in cells; M here is
//     M / max M + log_floor)
//   normalisation: the equilibrium of the chain with weights
//     w(i,j) = A(j) F_norm(i,j)
// the transition probabilities being the weights divided by the out-weight
// of the node. A map without contrast has no activation and contributes 0.
// The normalised maps are averaged within each channel, the channels
// combined with their weights, the grid map resized bilinearly to the
// input, blurred, and linearly stretched to [0, 1]. Like the original,
// the activation has a centre bias (a central cell has more neighbours
// within F_act): among many equal items the central ones score highest, so
// on a field of identical bars the odd one out wins only in the channel
// that sees it (tested for orientation).
//
// In: color, CV_8UC3 RGB, any size >= 1 x 1.
// Out: CV_32FC1 of color's size in [0, 1]; a uniform image gives an
// all-zero map.
// Errors: INVALID_ARGUMENT "color: empty" or "color: ... CV_8UC3" for bad
// input, the options field name for bad options.
absl::StatusOr<cv::Mat> ComputeHarelSaliency(const cv::Mat& color,
                                             const HarelOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_HAREL_H_
