#include "core/saliency/top_down.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/lab.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {

absl::Status Validate(const TargetColorOptions& options) {
  if (!(options.sigma_delta_e > 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "target_color.sigma_delta_e must be > 0, got ", options.sigma_delta_e));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeTargetColorSaliency(
    const cv::Mat& color, const TargetColorOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (color.empty() || color.type() != CV_8UC3) {
    return absl::InvalidArgumentError("color: must be a non-empty CV_8UC3");
  }
  // OpenCV's float Lab: L in [0, 100], a and b in about [-127, 127].
  cv::Mat rgb_f, lab;
  color.convertTo(rgb_f, CV_32FC3, 1.0 / 255.0);
  RgbToLab(rgb_f, &lab);
  cv::Mat target_rgb(1, 1, CV_32FC3,
                     cv::Scalar(options.rgb[0] / 255.0, options.rgb[1] / 255.0,
                                options.rgb[2] / 255.0));
  cv::Mat target_lab;
  RgbToLab(target_rgb, &target_lab);
  const cv::Vec3f t = target_lab.at<cv::Vec3f>(0, 0);
  const float inv = 0.5f / (options.sigma_delta_e * options.sigma_delta_e);
  cv::Mat map(color.size(), CV_32FC1);
  for (int v = 0; v < lab.rows; ++v) {
    const cv::Vec3f* in = lab.ptr<cv::Vec3f>(v);
    float* out = map.ptr<float>(v);
    for (int u = 0; u < lab.cols; ++u) {
      const cv::Vec3f d = in[u] - t;
      out[u] = std::exp(-d.dot(d) * inv);
    }
  }
  NormalizeLinear(map);
  return map;
}

absl::Status Validate(const LocationPriorOptions& options) {
  if (!(options.sigma_px > 0.0f) || !std::isfinite(options.sigma_px)) {
    return absl::InvalidArgumentError(
        absl::StrCat("location_prior.sigma_px must be finite and > 0, got ",
                     options.sigma_px));
  }
  if (!std::isfinite(options.u) || !std::isfinite(options.v)) {
    return absl::InvalidArgumentError(
        "location_prior: the centre must be finite");
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeLocationPrior(
    int width, int height, const LocationPriorOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (width <= 0 || height <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("location_prior: bad map size ", width, " x ", height));
  }
  // Separable: exp(-(du^2 + dv^2) / 2s^2) = gu(u) gv(v).
  const float inv = 0.5f / (options.sigma_px * options.sigma_px);
  std::vector<float> gu(width), gv(height);
  for (int u = 0; u < width; ++u) {
    gu[u] = std::exp(-(u - options.u) * (u - options.u) * inv);
  }
  for (int v = 0; v < height; ++v) {
    gv[v] = std::exp(-(v - options.v) * (v - options.v) * inv);
  }
  cv::Mat map(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    float* out = map.ptr<float>(v);
    for (int u = 0; u < width; ++u) out[u] = gv[v] * gu[u];
  }
  return map;
}

}  // namespace fovea
