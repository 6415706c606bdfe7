#include "core/baseline/pcl_clusters.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <new>
#include <unordered_map>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// Voxel coordinates are packed into 21 bits each; points farther than
// 2^20 voxels from the camera (5 km at 5 mm) are not clustered.
constexpr int64_t kVoxelCoordinateLimit = int64_t{1} << 20;

// The voxel grid of the masked points: one centroid per occupied voxel
// (what pcl::VoxelGrid outputs) and, unlike pcl::VoxelGrid without its
// memory-hungry leaf layout, the voxel of every pixel.
struct Voxels {
  Cloud::Ptr centroids{new Cloud};
  cv::Mat index;  // CV_32SC1, voxel of the pixel's point, -1 for none
};

Voxels Voxelize(const OrganizedCloud& cloud, const cv::Mat& mask, float leaf) {
  Voxels voxels;
  voxels.index = cv::Mat(cloud.height(), cloud.width(), CV_32SC1, -1);
  const double inverse_leaf = 1.0 / leaf;
  std::unordered_map<int64_t, int> by_key;
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const uint8_t* m = mask.ptr<uint8_t>(v);
    int* index = voxels.index.ptr<int>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (!m[u] || !std::isfinite(p[u][0]) || !std::isfinite(p[u][1]) ||
          !std::isfinite(p[u][2])) {
        continue;
      }
      int64_t key = 0;
      bool in_range = true;
      for (int axis = 0; axis < 3; ++axis) {
        const int64_t c = static_cast<int64_t>(
            std::floor(static_cast<double>(p[u][axis]) * inverse_leaf));
        if (c <= -kVoxelCoordinateLimit || c >= kVoxelCoordinateLimit) {
          in_range = false;
          break;
        }
        key = (key << 21) | (c + kVoxelCoordinateLimit);
      }
      if (!in_range) continue;
      const auto [it, inserted] =
          by_key.emplace(key, static_cast<int>(sums.size()));
      if (inserted) {
        sums.emplace_back(Eigen::Vector3d::Zero());
        counts.push_back(0);
      }
      sums[it->second] += Eigen::Vector3d(p[u][0], p[u][1], p[u][2]);
      ++counts[it->second];
      index[u] = it->second;
    }
  }
  voxels.centroids->reserve(sums.size());
  for (size_t i = 0; i < sums.size(); ++i) {
    const Eigen::Vector3d c = sums[i] / counts[i];
    voxels.centroids->push_back(pcl::PointXYZ(static_cast<float>(c.x()),
                                              static_cast<float>(c.y()),
                                              static_cast<float>(c.z())));
  }
  return voxels;
}

PixelClusters Cluster(const OrganizedCloud& cloud, const cv::Mat& mask,
                      const PclClustersOptions& options) {
  const Voxels voxels = Voxelize(cloud, mask, options.voxel_leaf);
  PixelClusters result;
  result.labels = cv::Mat(cloud.height(), cloud.width(), CV_32SC1, -1);
  const Cloud::Ptr& points = voxels.centroids;
  if (points->empty()) return result;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(
      new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(points);
  std::vector<pcl::PointIndices> clusters;
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(options.cluster_tolerance);
  ec.setMinClusterSize(options.min_cluster_points);
  ec.setMaxClusterSize(std::numeric_limits<int>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(points);
  ec.extract(clusters);  // sorted by size, largest first
  std::vector<int> voxel_cluster(points->size(), -1);
  for (size_t k = 0; k < clusters.size(); ++k) {
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (int i : clusters[k].indices) {
      voxel_cluster[i] = static_cast<int>(k);
      centroid += (*points)[i].getVector3fMap();
    }
    result.voxels.push_back(static_cast<int>(clusters[k].indices.size()));
    result.centroids.push_back(centroid /
                               static_cast<float>(result.voxels.back()));
  }
  for (int v = 0; v < cloud.height(); ++v) {
    const int* index = voxels.index.ptr<int>(v);
    int* label = result.labels.ptr<int>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (index[u] >= 0) label[u] = voxel_cluster[index[u]];
    }
  }
  return result;
}

std::vector<AttentionPoint> ClusterPoints(const OrganizedCloud& cloud,
                                          const PixelClusters& clusters,
                                          int max_points) {
  std::vector<AttentionPoint> result;
  const int count =
      std::min(static_cast<int>(clusters.voxels.size()), max_points);
  if (count <= 0) return result;
  // The pixel of each cluster nearest its centroid (voxel centroids are
  // not pixels).
  std::vector<float> best(count, std::numeric_limits<float>::max());
  std::vector<int> best_pixel(count, -1);
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const int* label = clusters.labels.ptr<int>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      const int k = label[u];
      if (k < 0 || k >= count) continue;
      const float d =
          (Eigen::Vector3f(p[u][0], p[u][1], p[u][2]) - clusters.centroids[k])
              .squaredNorm();
      if (d < best[k]) {
        best[k] = d;
        best_pixel[k] = v * cloud.width() + u;
      }
    }
  }
  const float largest = static_cast<float>(clusters.voxels[0]);
  for (int k = 0; k < count; ++k) {
    FOVEA_CHECK(best_pixel[k] >= 0);  // every cluster has a pixel
    AttentionPoint p;
    p.u = best_pixel[k] % cloud.width();
    p.v = best_pixel[k] / cloud.width();
    p.saliency = static_cast<float>(clusters.voxels[k]) / largest;
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

absl::StatusOr<PixelClusters> ClusterPixels(const OrganizedCloud& cloud,
                                            const cv::Mat& mask,
                                            const PclClustersOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (cloud.xyz.type() != CV_32FC3) {
    return absl::InvalidArgumentError("pcl_clusters: xyz must be CV_32FC3");
  }
  if (mask.type() != CV_8UC1 || mask.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "pcl_clusters: the mask must be CV_8UC1 of the cloud's size");
  }
  return Cluster(cloud, mask, options);
}

absl::StatusOr<std::vector<AttentionPoint>> DetectPclClusters(
    const OrganizedCloud& cloud, const TableScene& scene, int max_points,
    const PclClustersOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(PixelClusters clusters,
                         ClusterPixels(cloud, scene.candidate, options));
  return ClusterPoints(cloud, clusters, max_points);
}

}  // namespace fovea
