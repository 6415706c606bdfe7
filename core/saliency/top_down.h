#ifndef FOVEA_CORE_SALIENCY_TOP_DOWN_H_
#define FOVEA_CORE_SALIENCY_TOP_DOWN_H_

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

#include "absl/status/statusor.h"

namespace fovea {

// Top-down cues, the thesis's outlook ("bring me the yellow book"): maps a
// robot can weight in with the bottom-up channels.

struct TargetColorOptions {
  std::array<uint8_t, 3> rgb = {255, 255, 0};  // the requested colour
  // Colour distance at which similarity falls to exp(-1/2), CIE76 Delta E
  // in CIELAB units (about 2.3 is a just-noticeable difference; 20 keeps
  // shading of one surface colour together).
  float sigma_delta_e = 20.0f;
};

absl::Status Validate(const TargetColorOptions& options);

// Similarity of each pixel to the target colour in CIELAB:
// exp(-DeltaE^2 / (2 sigma^2)), in [0, 1], linearly normalised. `color` is
// CV_8UC3 RGB. A frame with no similar pixel gives small values everywhere,
// normalised so its best match is 1.
absl::StatusOr<cv::Mat> ComputeTargetColorSaliency(
    const cv::Mat& color, const TargetColorOptions& options);

struct LocationPriorOptions {
  float u = 0.0f;          // centre column, pixels
  float v = 0.0f;          // centre row, pixels
  float sigma_px = 80.0f;  // standard deviation, pixels, > 0
};

absl::Status Validate(const LocationPriorOptions& options);

// A Gaussian of the given centre and spread over a height x width map, 1 at
// the centre (where a person pointed, where the arm is, ...).
absl::StatusOr<cv::Mat> ComputeLocationPrior(
    int width, int height, const LocationPriorOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_TOP_DOWN_H_
