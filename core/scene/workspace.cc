#include "core/scene/workspace.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"

namespace fovea {

absl::Status Validate(const Workspace& workspace) {
  for (const auto& [field, value] :
       {std::pair<const char*, float>{"min_depth_m", workspace.min_depth_m},
        {"max_depth_m", workspace.max_depth_m}}) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "workspace.", field, " must be finite and >= 0, got ", value));
    }
  }
  if (workspace.max_depth_m > 0.0f &&
      !(workspace.max_depth_m > workspace.min_depth_m)) {
    return absl::InvalidArgumentError(
        absl::StrCat("workspace.max_depth_m must exceed min_depth_m, got ",
                     workspace.max_depth_m, " <= ", workspace.min_depth_m));
  }
  if (workspace.box.has_value()) {
    const Workspace::Box& b = *workspace.box;
    if (!b.min.allFinite() || !b.max.allFinite()) {
      return absl::InvalidArgumentError(
          "workspace.box: min and max must be finite");
    }
    for (int i = 0; i < 3; ++i) {
      if (!(b.max[i] > b.min[i])) {
        return absl::InvalidArgumentError(absl::StrCat(
            "workspace.box is empty: max.", std::string(1, "xyz"[i]), " (",
            b.max[i], ") must exceed min (", b.min[i], ")"));
      }
    }
  }
  return absl::OkStatus();
}

DepthRange EffectiveDepthRange(const Workspace& workspace,
                               const SensorModel& sensor) {
  DepthRange range;
  range.min_m =
      workspace.min_depth_m > 0.0f ? workspace.min_depth_m : sensor.min_range_m;
  range.max_m =
      workspace.max_depth_m > 0.0f ? workspace.max_depth_m : sensor.max_range_m;
  if (range.max_m <= range.min_m) range.min_m = 0.0f;  // a near max given
  return range;
}

int ApplyWorkspace(const Workspace& workspace, const SensorModel& sensor,
                   OrganizedCloud& cloud) {
  const DepthRange range = EffectiveDepthRange(workspace, sensor);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  int removed = 0;
  for (int v = 0; v < cloud.height(); ++v) {
    cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      const float z = p[u][2];
      if (std::isnan(z)) continue;
      bool keep = z >= range.min_m && z <= range.max_m;
      if (keep && workspace.box.has_value()) {
        const Workspace::Box& b = *workspace.box;
        for (int i = 0; i < 3 && keep; ++i) {
          keep = p[u][i] >= b.min[i] && p[u][i] <= b.max[i];
        }
      }
      if (!keep) {
        p[u] = cv::Vec3f(nan, nan, nan);
        ++removed;
      }
    }
  }
  return removed;
}

}  // namespace fovea
