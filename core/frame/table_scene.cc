#include "core/frame/table_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"

namespace fovea {

absl::Status Validate(const TableSceneOptions& options) {
  if (!(options.min_object_height >= 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("table_scene.min_object_height must be >= 0, got ",
                     options.min_object_height));
  }
  if (!(options.max_object_height > options.min_object_height)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "table_scene.max_object_height must exceed min_object_height, got ",
        options.max_object_height));
  }
  if (!(options.min_height_sigmas >= 0.0f) || !(options.sigma0_m >= 0.0f) ||
      !(options.sigma_per_z2 >= 0.0f)) {
    return absl::InvalidArgumentError(
        "table_scene.min_height_sigmas, sigma0_m and sigma_per_z2 must be >= "
        "0");
  }
  if (!(options.hull_margin >= 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "table_scene.hull_margin must be >= 0, got ", options.hull_margin));
  }
  return absl::OkStatus();
}

TableScene PrepareTableScene(const OrganizedCloud& cloud,
                             const SupportPlane& plane,
                             const TableSceneOptions& options) {
  TableScene scene;
  const int w = cloud.width(), h = cloud.height();
  scene.height.create(h, w, CV_32FC1);
  scene.candidate.create(h, w, CV_8UC1);
  scene.candidate.setTo(cv::Scalar(0));
  scene.region.create(h, w, CV_8UC1);
  scene.region.setTo(cv::Scalar(0));
  const bool have_inliers = plane.inliers.rows == h && plane.inliers.cols == w;
  const Eigen::Vector3f& n = plane.normal;
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    float* height = scene.height.ptr<float>(v);
    uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    uint8_t* region = scene.region.ptr<uint8_t>(v);
    const uint8_t* inlier =
        have_inliers ? plane.inliers.ptr<uint8_t>(v) : nullptr;
    for (int u = 0; u < w; ++u) {
      if (std::isnan(p[u][2])) {
        height[u] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float hgt =
          n.x() * p[u][0] + n.y() * p[u][1] + n.z() * p[u][2] + plane.d;
      height[u] = hgt;
      const float z = p[u][2];
      const float min_height =
          std::max(options.min_object_height,
                   options.min_height_sigmas *
                       (options.sigma0_m + options.sigma_per_z2 * z * z));
      const bool on_plane = inlier != nullptr && inlier[u];
      if (on_plane) region[u] = 255;
      if (hgt > options.max_object_height) continue;
      if (hgt <= min_height && (on_plane || hgt < -min_height)) continue;
      const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
      if (!plane.ProjectsInsideHull(q)) continue;
      region[u] = 255;
      if (hgt <= min_height) continue;
      if (plane.ProjectsInsideHull(q, options.hull_margin)) {
        cand[u] = 255;
        ++scene.candidate_count;
      }
    }
  }
  return scene;
}

}  // namespace fovea
