#ifndef FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_
#define FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"

namespace fovea {

// A saliency map is a CV_32FC1 cv::Mat the size of the frame with values in
// [0, 1]; 0 where nothing is salient or there is no data.

// Linear normalisation (thesis eq. 2.37): divides by the maximum so the map
// spans [0, 1] (the minimum of a saliency map is 0 by construction: the
// table). A map that is all zero stays zero. In place.
void NormalizeLinear(cv::Mat& map);

// The colour operators' input check: INVALID_ARGUMENT "color: empty" or
// "color: must be CV_8UC3 (RGB) ..." unless `color` is a non-empty CV_8UC3.
absl::Status CheckColorImage(const cv::Mat& color);

// The colour operators' shared options check: the three feature weights
// (intensity, colour, orientation) are finite, >= 0 and not all 0, and the
// Gabor kernel size is odd in [3, 63]. Messages name the field as
// "<op>.intensity_weight", "<op>.gabor_kernel_size", ...
absl::Status CheckFeatureWeights(const char* op, float intensity_weight,
                                 float color_weight, float orientation_weight);
absl::Status CheckGaborKernelSize(const char* op, int gabor_kernel_size);

// Stretches `map` linearly to [0, 1] in place (minimum to 0, maximum to 1,
// CV_32F). A map whose range is at most `relative_flat_tolerance` times its
// largest magnitude is flat and becomes all zero.
void StretchToUnit(cv::Mat& map, double relative_flat_tolerance);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_
