#include "core/pyramid/fusion.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

absl::Status ValidateInputs(const std::vector<cv::Mat>& maps,
                            const std::vector<float>& weights) {
  if (maps.empty()) {
    return absl::InvalidArgumentError("fusion needs at least one map");
  }
  if (weights.size() != maps.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("fusion needs one weight per map: ", maps.size(),
                     " maps, ", weights.size(), " weights"));
  }
  float weight_sum = 0.0f;
  for (size_t i = 0; i < maps.size(); ++i) {
    if (!(weights[i] >= 0.0f) || !std::isfinite(weights[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "fusion weights[", i, "] must be finite and >= 0, got ", weights[i]));
    }
    weight_sum += weights[i];
    if (maps[i].empty() || maps[i].type() != CV_32FC1) {
      return absl::InvalidArgumentError(
          absl::StrCat("fusion maps[", i, "] must be a non-empty CV_32FC1"));
    }
    if (maps[i].size() != maps[0].size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "fusion maps[", i, "] is ", maps[i].cols, "x", maps[i].rows,
          ", maps[0] is ", maps[0].cols, "x", maps[0].rows));
    }
  }
  if (!(weight_sum > 0.0f)) {
    return absl::InvalidArgumentError(
        "fusion weights must not all be 0 (they are renormalised to sum "
        "to 1)");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<cv::Mat> FuseChannels(const std::vector<cv::Mat>& maps,
                                     const std::vector<float>& weights,
                                     ChannelFusion fusion) {
  FOVEA_RETURN_IF_ERROR(ValidateInputs(maps, weights));
  double norm = 0.0;
  for (float w : weights) {
    norm = fusion == ChannelFusion::kSum ? norm + w : std::max(norm, double{w});
  }
  cv::Mat out = cv::Mat::zeros(maps[0].size(), CV_32FC1);
  bool first = true;
  for (size_t i = 0; i < maps.size(); ++i) {
    const double w = weights[i] / norm;
    if (w <= 0.0) continue;
    if (fusion == ChannelFusion::kSum) {
      cv::scaleAdd(maps[i], w, out, out);
    } else if (first) {
      maps[i].convertTo(out, CV_32FC1, w);
    } else {
      cv::max(out, maps[i] * w, out);
    }
    first = false;
  }
  return out;
}

}  // namespace fovea
