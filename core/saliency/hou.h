#ifndef FOVEA_CORE_SALIENCY_HOU_H_
#define FOVEA_CORE_SALIENCY_HOU_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

struct HouOptions {
  // Width of the grey image the spectrum is taken of, px, >= 8; the height
  // keeps the aspect ratio (Hou & Zhang 2007: 64 px).
  int working_width = 64;
  // Side of the box filter h_n that averages the log amplitude spectrum,
  // odd, >= 3 (Hou & Zhang 2007: n = 3).
  int average_size = 3;
  // Sigma of the Gaussian g that smooths the squared magnitude, px at the
  // working width, > 0. The paper gives sigma = 8 without saying at
  // which resolution; Hou's published MATLAB code smooths the 64 px map with
  // fspecial('gaussian', [10 10], 2.5), which we follow.
  double blur_sigma_px = 2.5;
  // Transform the image mirrored into a 2w x 2h tile instead of the image
  // itself. The DFT treats its input as periodic; the jump between opposite
  // borders of a real frame is the strongest "unexpected" structure and
  // lights up the corners. Mirroring makes the tile continuous (ours; not in
  // the paper).
  bool mirror_border = true;
};

absl::Status Validate(const HouOptions& options);

// Spectral residual saliency (Hou & Zhang, "Saliency Detection: A Spectral
// Residual Approach", CVPR 2007). With I the grey image (ITU-R 601 luma in
// [0, 1]) resized to options.working_width and F the 2D DFT:
//   A(f) = |F[I](f)|, P(f) = arg F[I](f)
//   L(f) = log A(f), R(f) = L(f) - h_n * L(f)
//   S(x) = g * |F^-1[exp(R(f) + i P(f))]|^2
// h_n is the n x n box average (border replicated), g a Gaussian. Bins
// whose amplitude is below kHouAmplitudeFloor times the largest amplitude
// carry no phase; they are left out of the inverse transform (and enter the
// box average at the floor) so that log 0 never happens. With
// mirror_border, I is first mirrored into a 2w x 2h tile and S cropped
// back to w x h.
//
// In: color, CV_8UC3 RGB, any size >= 1 x 1.
// Out: CV_32FC1 of color's size, S resized bilinearly and linearly
// stretched to [0, 1] (min -> 0, max -> 1); an image without structure
// (a uniform one) gives an all-zero map.
// Errors: INVALID_ARGUMENT "color: empty" or "color: ... CV_8UC3" for bad
// input, the options field name for bad options.
absl::StatusOr<cv::Mat> ComputeHouSaliency(const cv::Mat& color,
                                           const HouOptions& options);

// Relative floor on the amplitude spectrum, see above (ours: float
// round-off of a DFT of size 64 x 48 is ~1e-7 relative).
inline constexpr float kHouAmplitudeFloor = 1e-5f;

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_HOU_H_
