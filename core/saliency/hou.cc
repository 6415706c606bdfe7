#include "core/saliency/hou.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// A map whose range is below this fraction of its largest magnitude is
// round-off of a structureless input and becomes all zero (ours).
constexpr double kRelativeFlatTolerance = 1e-4;

// Grey image (luma in [0, 1]) at the working width.
cv::Mat WorkingGrey(const cv::Mat& color, int working_width) {
  cv::Mat grey8, grey;
  cv::cvtColor(color, grey8, cv::COLOR_RGB2GRAY);
  grey8.convertTo(grey, CV_32F, 1.0 / 255.0);
  const int h = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(working_width) *
                                      color.rows / color.cols)));
  cv::Mat small;
  cv::resize(grey, small, cv::Size(working_width, h), 0, 0,
             working_width < color.cols ? cv::INTER_AREA : cv::INTER_LINEAR);
  return small;
}

// |F^-1[exp(R + iP)]|^2 of a real image (hou.h, without the smoothing).
cv::Mat SpectralResidualEnergy(const cv::Mat& grey, int average_size) {
  cv::Mat spectrum;
  cv::dft(grey, spectrum, cv::DFT_COMPLEX_OUTPUT);
  cv::Mat planes[2];
  cv::split(spectrum, planes);
  cv::Mat amplitude, phase;
  cv::cartToPolar(planes[0], planes[1], amplitude, phase);
  double max_amplitude = 0.0;
  cv::minMaxLoc(amplitude, nullptr, &max_amplitude);
  const float floor = kHouAmplitudeFloor * static_cast<float>(max_amplitude);
  if (floor <= 0.0f) return cv::Mat::zeros(grey.size(), CV_32F);
  const cv::Mat carries_phase = amplitude > floor;
  cv::Mat log_amplitude;
  cv::max(amplitude, floor, log_amplitude);
  cv::log(log_amplitude, log_amplitude);
  cv::Mat average;
  cv::blur(log_amplitude, average, cv::Size(average_size, average_size),
           cv::Point(-1, -1), cv::BORDER_REPLICATE);
  cv::Mat residual_amplitude;
  cv::exp(log_amplitude - average, residual_amplitude);
  residual_amplitude.setTo(0, ~carries_phase);
  cv::polarToCart(residual_amplitude, phase, planes[0], planes[1]);
  cv::merge(planes, 2, spectrum);
  cv::Mat image;
  cv::idft(spectrum, image, cv::DFT_COMPLEX_OUTPUT | cv::DFT_SCALE);
  cv::split(image, planes);
  cv::Mat energy;
  cv::magnitude(planes[0], planes[1], energy);
  return energy.mul(energy);
}

}  // namespace

absl::Status Validate(const HouOptions& options) {
  if (options.working_width < 8) {
    return absl::InvalidArgumentError(absl::StrCat(
        "hou.working_width must be >= 8, got ", options.working_width));
  }
  if (options.average_size < 3 || options.average_size % 2 == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "hou.average_size must be odd and >= 3, got ", options.average_size));
  }
  if (!(options.blur_sigma_px > 0.0 && std::isfinite(options.blur_sigma_px))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "hou.blur_sigma_px must be > 0, got ", options.blur_sigma_px));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeHouSaliency(const cv::Mat& color,
                                           const HouOptions& options) {
  FOVEA_RETURN_IF_ERROR(CheckColorImage(color));
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const cv::Mat grey = WorkingGrey(color, options.working_width);
  cv::Mat signal = grey;
  if (options.mirror_border) {
    cv::copyMakeBorder(grey, signal, 0, grey.rows, 0, grey.cols,
                       cv::BORDER_REFLECT);
  }
  cv::Mat energy = SpectralResidualEnergy(signal, options.average_size);
  cv::GaussianBlur(energy, energy, cv::Size(0, 0), options.blur_sigma_px,
                   options.blur_sigma_px, cv::BORDER_REPLICATE);
  cv::Mat map;
  cv::resize(energy(cv::Rect(0, 0, grey.cols, grey.rows)), map, color.size(), 0,
             0, cv::INTER_LINEAR);
  StretchToUnit(map, kRelativeFlatTolerance);
  return map;
}

}  // namespace fovea
