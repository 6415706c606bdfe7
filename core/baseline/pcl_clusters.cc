#include "core/baseline/pcl_clusters.h"

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <new>

#include "absl/strings/str_cat.h"

namespace fovea {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr Candidates(const OrganizedCloud& cloud, const TableScene& scene,
                      std::vector<int>& pixels) {
  Cloud::Ptr points(new Cloud);
  points->reserve(scene.candidate_count);
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const uint8_t* c = scene.candidate.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (!c[u]) continue;
      points->push_back(pcl::PointXYZ(p[u][0], p[u][1], p[u][2]));
      pixels.push_back(v * cloud.width() + u);
    }
  }
  return points;
}

std::vector<AttentionPoint> Cluster(const OrganizedCloud& cloud,
                                    const TableScene& scene, int max_points,
                                    const PclClustersOptions& options) {
  std::vector<int> pixels;
  const Cloud::Ptr points = Candidates(cloud, scene, pixels);
  if (points->empty()) return {};
  Cloud::Ptr filtered(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> voxel;
  voxel.setInputCloud(points);
  voxel.setLeafSize(options.voxel_leaf, options.voxel_leaf, options.voxel_leaf);
  voxel.filter(*filtered);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(
      new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(filtered);
  std::vector<pcl::PointIndices> clusters;
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(options.cluster_tolerance);
  ec.setMinClusterSize(options.min_cluster_points);
  ec.setMaxClusterSize(std::numeric_limits<int>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(filtered);
  ec.extract(clusters);  // sorted by size, largest first
  std::vector<AttentionPoint> result;
  if (clusters.empty()) return result;
  const float largest = static_cast<float>(clusters[0].indices.size());
  for (const pcl::PointIndices& cluster : clusters) {
    if (static_cast<int>(result.size()) >= max_points) break;
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (int i : cluster.indices) centroid += (*filtered)[i].getVector3fMap();
    centroid /= static_cast<float>(cluster.indices.size());
    // The nearest candidate pixel (voxel centroids are not pixels).
    float best = std::numeric_limits<float>::max();
    int best_pixel = -1;
    for (size_t k = 0; k < points->size(); ++k) {
      const float d = ((*points)[k].getVector3fMap() - centroid).squaredNorm();
      if (d < best) {
        best = d;
        best_pixel = pixels[k];
      }
    }
    AttentionPoint p;
    p.u = best_pixel % cloud.width();
    p.v = best_pixel / cloud.width();
    p.saliency = static_cast<float>(cluster.indices.size()) / largest;
    result.push_back(p);
  }
  return result;
}

}  // namespace

absl::Status Validate(const PclClustersOptions& options) {
  if (!(options.cluster_tolerance > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("pcl_clusters.cluster_tolerance must be > 0, got ",
                     options.cluster_tolerance));
  }
  if (options.min_cluster_points < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("pcl_clusters.min_cluster_points must be >= 1, got ",
                     options.min_cluster_points));
  }
  if (!(options.voxel_leaf > 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "pcl_clusters.voxel_leaf must be > 0, got ", options.voxel_leaf));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<AttentionPoint>> DetectPclClusters(
    const OrganizedCloud& cloud, const TableScene& scene, int max_points,
    const PclClustersOptions& options) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  try {
    return Cluster(cloud, scene, max_points, options);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError("pcl_clusters: out of memory");
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("pcl_clusters: ", e.what()));
  }
}

}  // namespace fovea
