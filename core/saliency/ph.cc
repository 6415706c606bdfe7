#include "core/saliency/ph.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {

absl::Status Validate(const PhOptions& options) {
  if (!(options.top_offset_fraction >= 0.0f &&
        options.top_offset_fraction < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("ph.top_offset_fraction must be in [0, 1), got ",
                     options.top_offset_fraction));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputePhSaliency(const TableScene& scene,
                                          const PhOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const int w = scene.height.cols, h = scene.height.rows;
  cv::Mat map(h, w, CV_32FC1, cv::Scalar(0));
  float tallest = 0.0f;
  for (int v = 0; v < h; ++v) {
    const float* height = scene.height.ptr<float>(v);
    const uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      if (cand[u]) tallest = std::max(tallest, height[u]);
    }
  }
  if (tallest <= 0.0f) return map;
  const float preferred = (1.0f - options.top_offset_fraction) * tallest;
  const float inv = 1.0f / preferred;
  for (int v = 0; v < h; ++v) {
    const float* height = scene.height.ptr<float>(v);
    const uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    float* out = map.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      if (!cand[u]) continue;
      const float t = 1.0f - height[u] * inv;
      out[u] = std::clamp(1.0f - t * t, 0.0f, 1.0f);
    }
  }
  NormalizeLinear(map);
  return map;
}

}  // namespace fovea
