#include "core/frame/table_scene.h"

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
  const Eigen::Vector3f& n = plane.normal;
  for (int v = 0; v < h; ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    float* height = scene.height.ptr<float>(v);
    uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      if (std::isnan(p[u][2])) {
        height[u] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float hgt =
          n.x() * p[u][0] + n.y() * p[u][1] + n.z() * p[u][2] + plane.d;
      height[u] = hgt;
      if (hgt <= options.min_object_height || hgt > options.max_object_height) {
        continue;
      }
      if (plane.ProjectsInsideHull({p[u][0], p[u][1], p[u][2]},
                                   options.hull_margin)) {
        cand[u] = 255;
        ++scene.candidate_count;
      }
    }
  }
  return scene;
}

}  // namespace fovea
