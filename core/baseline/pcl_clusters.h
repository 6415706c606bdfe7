#ifndef FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_
#define FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/attention/attention_point.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/table_scene.h"

namespace fovea {

// The detector a robotics engineer writes first, as the peer the attention
// system is measured against (issue 3): with the support plane removed,
// cluster what stands on it with PCL's Euclidean clustering and attend to
// each cluster's point nearest its centroid, largest cluster first.
struct PclClustersOptions {
  // Euclidean cluster tolerance, metres (PCL tutorial value: 2 cm).
  float cluster_tolerance = 0.02f;
  // Smallest cluster, points of the voxel-filtered cloud.
  int min_cluster_points = 30;
  // Voxel grid leaf before clustering, metres (speed; PCL tutorial: 1 cm).
  float voxel_leaf = 0.005f;
};

absl::Status Validate(const PclClustersOptions& options);

// Candidates of `scene` (points on the table, see TableScene) are
// voxel-filtered and clustered; each cluster yields the candidate pixel
// whose point is nearest the cluster's centroid. Points come largest
// cluster first, at most `max_points`; saliency = cluster size / largest
// cluster size. No candidates: no points.
absl::StatusOr<std::vector<AttentionPoint>> DetectPclClusters(
    const OrganizedCloud& cloud, const TableScene& scene, int max_points,
    const PclClustersOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_
