#include "core/saliency/saliency_map.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace fovea {

void NormalizeLinear(cv::Mat& map) {
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  if (max_value > 0.0) map *= 1.0 / max_value;
}

absl::Status CheckColorImage(const cv::Mat& color) {
  if (color.empty()) return absl::InvalidArgumentError("color: empty");
  if (color.type() != CV_8UC3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "color: must be CV_8UC3 (RGB), got OpenCV type ", color.type()));
  }
  return absl::OkStatus();
}

absl::Status CheckFeatureWeights(const char* op, float intensity_weight,
                                 float color_weight, float orientation_weight) {
  const std::pair<const char*, float> weights[] = {
      {"intensity_weight", intensity_weight},
      {"color_weight", color_weight},
      {"orientation_weight", orientation_weight},
  };
  for (const auto& [field, value] : weights) {
    if (!(value >= 0.0f && std::isfinite(value))) {
      return absl::InvalidArgumentError(
          absl::StrCat(op, ".", field, " must be >= 0, got ", value));
    }
  }
  if (!(intensity_weight + color_weight + orientation_weight > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat(op,
                     ".intensity_weight + color_weight + orientation_weight "
                     "must be > 0"));
  }
  return absl::OkStatus();
}

absl::Status CheckGaborKernelSize(const char* op, int gabor_kernel_size) {
  if (gabor_kernel_size < 3 || gabor_kernel_size % 2 == 0 ||
      gabor_kernel_size > 63) {
    return absl::InvalidArgumentError(
        absl::StrCat(op, ".gabor_kernel_size must be odd in [3, 63], got ",
                     gabor_kernel_size));
  }
  return absl::OkStatus();
}

void StretchToUnit(cv::Mat& map, double relative_flat_tolerance) {
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(map, &lo, &hi);
  const double scale = std::max(std::abs(lo), std::abs(hi));
  if (scale == 0.0 || hi - lo <= relative_flat_tolerance * scale) {
    map.setTo(0);
    return;
  }
  map.convertTo(map, CV_32F, 1.0 / (hi - lo), -lo / (hi - lo));
  // Round-off of the affine map can leave -1e-18 or 1 + 1e-7.
  cv::min(cv::max(map, 0.0), 1.0, map);
}

}  // namespace fovea
