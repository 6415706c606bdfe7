#include "core/saliency/rso.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {
constexpr float kRightAngle = static_cast<float>(M_PI / 2.0);
constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
}  // namespace

absl::Status Validate(const RsoOptions& options) {
  if (!(options.preferred_angle_deg >= 0.0f &&
        options.preferred_angle_deg <= 90.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rso.preferred_angle_deg must be in [0, 90], got ",
                     options.preferred_angle_deg));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeRsoSaliency(const OrganizedCloud& cloud,
                                           const SupportPlane& plane,
                                           const TableScene& scene,
                                           const RsoOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const int w = cloud.width(), h = cloud.height();
  cv::Mat map(h, w, CV_32FC1, cv::Scalar(0));
  const float preferred = options.preferred_angle_deg * kDegToRad;
  const Eigen::Vector3f& t = plane.normal;
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    const uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    float* out = map.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      if (!cand[u] || std::isnan(n[u][2])) continue;
      const float c = std::clamp(
          t.x() * n[u][0] + t.y() * n[u][1] + t.z() * n[u][2], -1.0f, 1.0f);
      const float angle = std::acos(c);
      out[u] = std::max(0.0f, 1.0f - std::abs(angle - preferred) / kRightAngle);
    }
  }
  NormalizeLinear(map);
  return map;
}

}  // namespace fovea
