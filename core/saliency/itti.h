#ifndef FOVEA_CORE_SALIENCY_ITTI_H_
#define FOVEA_CORE_SALIENCY_ITTI_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

struct IttiOptions {
  // Centre levels c of the centre-surround maps, min..max, pyramid level 0 =
  // the input (Itti, Koch & Niebur 1998, sec. II: c in {2, 3, 4}).
  int min_center_level = 2;
  int max_center_level = 4;
  // Centre-surround offsets d, s = c + d, min..max, >= 1 (Itti 1998: d in
  // {3, 4}). max_center_level + max_delta <= kIttiMaxPyramidLevel.
  int min_delta = 3;
  int max_delta = 4;
  // Pyramid level at which feature maps are summed across scales into
  // conspicuity maps and combined (Itti 1998, eq. 5-7: level 4).
  int map_level = 4;
  // Gabor filter on each intensity level, px of that level: wavelength,
  // envelope sigma, odd kernel side (Walther's SaliencyToolbox defaults: 7,
  // 2.33, 9). A quadrature pair (phases 0 and 90 deg) gives the energy.
  double gabor_wavelength_px = 7.0;
  double gabor_sigma_px = 2.33;
  int gabor_kernel_size = 9;
  // r, g, b are divided by I only where I exceeds this fraction of its
  // maximum over the image, else the colour channels are 0 (Itti 1998,
  // sec. II: 1/10), [0, 1).
  float color_intensity_threshold = 0.1f;
  // N(.) ignores local maxima below this fraction of the global maximum
  // (SaliencyToolbox maxNormalizeLocalMax: 1/10), [0, 1).
  float local_max_threshold = 0.1f;
  // Weights of the intensity, colour and orientation conspicuity maps in the
  // saliency map, >= 0 with a positive sum (Itti 1998, eq. 8: equal).
  float intensity_weight = 1.0f;
  float color_weight = 1.0f;
  float orientation_weight = 1.0f;
};

// Deepest pyramid level an IttiOptions may ask for (ours: level 10 of a
// 640 x 480 frame is already 1 x 1).
inline constexpr int kIttiMaxPyramidLevel = 10;

absl::Status Validate(const IttiOptions& options);

// Colour saliency of Itti, Koch & Niebur, "A Model of Saliency-Based Visual
// Attention for Rapid Scene Analysis", PAMI 1998. With r, g, b in [0, 1]:
//   I = (r + g + b) / 3; r, g, b divided by I where I > threshold * max I
//   R = r - (g + b)/2, G = g - (r + b)/2, B = b - (r + g)/2,
//   Y = (r + g)/2 - |r - g|/2 - b, negatives set to 0       (sec. II)
// each in a dyadic Gaussian pyramid (cv::pyrDown, 5-tap), O(sigma, theta)
// the Gabor energy of I(sigma) at theta in {0, 45, 90, 135} deg. Centre-
// surround with s interpolated to c (the "-(-)" of the paper):
//   I(c,s) = |I(c) - I(s)|                                    (eq. 1)
//   RG(c,s) = |(R - G)(c) - (R - G)(s)|                       (eq. 2)
//   BY(c,s) = |(B - Y)(c) - (B - Y)(s)|                       (eq. 3)
//   O(c,s,theta) = |O(c,theta) - O(s,theta)|                  (eq. 4)
// (eq. 2-3 as implemented by Itti's and Walther's code: the opponency at c
// minus the same opponency at s). N(.) scales a map to [0, 1] and multiplies
// it by (1 - m)^2, m the mean of its local maxima (8-neighbourhood, ties
// broken in raster order, >= local_max_threshold) other than the global
// one. Conspicuity maps at map_level:
//   Ib = sum N(I(c,s)), Cb = sum [N(RG(c,s)) + N(BY(c,s))],
//   Ob = sum_theta N(sum N(O(c,s,theta)))                     (eq. 5-7)
//   S = (wI N(Ib) + wC N(Cb) + wO N(Ob)) / (wI + wC + wO)     (eq. 8)
//
// In: color, CV_8UC3 RGB, any size >= 1 x 1 (levels of a tiny image go down
// to 1 x 1 and then carry no contrast).
// Out: CV_32FC1 of color's size, S resized bilinearly and linearly
// stretched to [0, 1]; a uniform image gives an all-zero map.
// Errors: INVALID_ARGUMENT "color: empty" or "color: ... CV_8UC3" for bad
// input, the options field name for bad options.
absl::StatusOr<cv::Mat> ComputeIttiSaliency(const cv::Mat& color,
                                            const IttiOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_ITTI_H_
