#ifndef FOVEA_CORE_SCENE_TABLE_SCENE_INTERNAL_H_
#define FOVEA_CORE_SCENE_TABLE_SCENE_INTERNAL_H_

// What table_scene.cc and beyond_hull.cc share; not part of core's API.

#include <Eigen/Core>
#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea::table_scene_internal {

// Within this height of the support a point at depth z is table:
// max(min_object_height, min_height_sigmas * (sigma0_m + sigma_per_z2 z^2)),
// metres (TableSceneOptions::min_object_height).
inline float TableNoiseBand(float z, const TableSceneOptions& o) {
  return std::max(o.min_object_height,
                  o.min_height_sigmas * (o.sigma0_m + o.sigma_per_z2 * z * z));
}

// Whether p (normal m, NaN when none) lies on one of the structures.
bool OnStructure(const std::vector<TableScene::Plane>& structures,
                 const Eigen::Vector3f& p, const cv::Vec3f& m,
                 const TableSceneOptions& o);

// Adds to `scene` (region, standing and candidate, candidate_count kept)
// what rests on the table beyond the hull of its visible top
// (TableSceneOptions::rest_beyond_hull_m and rest_on_hidden_table): the
// parts that the candidates reach without a jump in depth, and the parts
// that stand on the table where the camera does not see it; neither wider
// than max_resting_size_m. Nothing when rest_beyond_hull_m is 0 or the
// plane has no hull.
void AddWhatRestsBeyondHull(const OrganizedCloud& cloud,
                            const SupportPlane& plane,
                            const TableSceneOptions& options,
                            TableScene& scene);

}  // namespace fovea::table_scene_internal

#endif  // FOVEA_CORE_SCENE_TABLE_SCENE_INTERNAL_H_
