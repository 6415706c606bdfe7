#ifndef FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_
#define FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/attention/attention_point.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/table_scene.h"

namespace fovea {

// The detector a robotics engineer writes first, as the peer the attention
// system is measured against: with the support plane removed,
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

// Euclidean clusters of the points of the pixels of `mask`, the step
// DetectPclClusters and SegmentSceneEuclidean (scene_segmenters.h) share:
// the points are voxel-filtered (each voxel becomes the centroid of its
// points, as pcl::VoxelGrid does) and the voxel centroids clustered with
// pcl::EuclideanClusterExtraction; every pixel takes its voxel's cluster.
struct PixelClusters {
  // CV_32SC1 of the cloud's size: cluster index, 0 the largest cluster
  // (most voxels); -1 outside `mask`, without a point, or in a cluster of
  // fewer than min_cluster_points voxels.
  cv::Mat labels;
  std::vector<int> voxels;                 // per cluster, voxel count
  std::vector<Eigen::Vector3f> centroids;  // per cluster, mean voxel, m
};

// `mask`: CV_8UC1 of the cloud's size, non-zero = cluster this pixel's
// point (pixels without a point are skipped). An empty mask gives no
// clusters (labels all -1). INVALID_ARGUMENT for bad options or a mask or
// cloud of the wrong type or size.
absl::StatusOr<PixelClusters> ClusterPixels(const OrganizedCloud& cloud,
                                            const cv::Mat& mask,
                                            const PclClustersOptions& options);

// Candidates of `scene` (points on the table, see TableScene) are
// clustered (ClusterPixels); each cluster yields its pixel whose point is
// nearest the cluster's centroid. Points come largest
// cluster first, at most `max_points`; saliency = cluster size / largest
// cluster size. No candidates: no points.
absl::StatusOr<std::vector<AttentionPoint>> DetectPclClusters(
    const OrganizedCloud& cloud, const TableScene& scene, int max_points,
    const PclClustersOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_BASELINE_PCL_CLUSTERS_H_
