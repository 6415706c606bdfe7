#include "core/baseline/scene_segmenters.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/planar_region.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <new>
#include <numeric>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/scene/support_plane.h"

namespace fovea {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// The frame size PclSupportOptions::min_inliers is given for.
constexpr double kReferencePixels = 640.0 * 480.0;
// Colour of points when the cloud has none (LCCP's colour term then sees
// no difference).
constexpr uint8_t kGrey = 128;

absl::Status CheckCloud(const OrganizedCloud& cloud) {
  if (cloud.xyz.type() != CV_32FC3) {
    return absl::InvalidArgumentError("scene segmenter: xyz must be CV_32FC3");
  }
  if (cloud.normals.type() != CV_32FC3 ||
      cloud.normals.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "scene segmenter: normals must be CV_32FC3 of xyz's size");
  }
  if (!cloud.color.empty() && (cloud.color.type() != CV_8UC3 ||
                               cloud.color.size() != cloud.xyz.size())) {
    return absl::InvalidArgumentError(
        "scene segmenter: color must be empty or CV_8UC3 of xyz's size");
  }
  return absl::OkStatus();
}

bool HasAnyPoint(const OrganizedCloud& cloud) {
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (std::isfinite(p[u][2])) return true;
    }
  }
  return false;
}

SceneSegmentation NoSegments(const OrganizedCloud& cloud) {
  SceneSegmentation result;
  result.labels = cv::Mat(cloud.height(), cloud.width(), CV_32SC1, -1);
  return result;
}

// The organized PCL clouds of `cloud`'s points and normals (NaN where
// either is missing, so that no plane takes a point without a normal).
void ToPcl(const OrganizedCloud& cloud, pcl::PointCloud<pcl::PointXYZ>& points,
           pcl::PointCloud<pcl::Normal>& normals) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points = pcl::PointCloud<pcl::PointXYZ>(cloud.width(), cloud.height());
  normals = pcl::PointCloud<pcl::Normal>(cloud.width(), cloud.height());
  points.is_dense = false;
  normals.is_dense = false;
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      pcl::PointXYZ& q = points.at(u, v);
      pcl::Normal& m = normals.at(u, v);
      q.x = p[u][0];
      q.y = p[u][1];
      q.z = p[u][2];
      const bool valid = std::isfinite(p[u][2]) && std::isfinite(n[u][2]);
      m.normal_x = valid ? n[u][0] : nan;
      m.normal_y = valid ? n[u][1] : nan;
      m.normal_z = valid ? n[u][2] : nan;
      m.curvature = valid ? 0.0f : nan;
    }
  }
}

// PCL's organized multi-plane segmentation; the largest plane facing the
// camera's up is the support. NOT_FOUND when there is none.
absl::StatusOr<SupportPlane> FindPclSupportPlane(
    const OrganizedCloud& cloud, const PclSupportOptions& options) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(
      new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  ToPcl(cloud, *points, *normals);

  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label>
      mps;
  const double scale =
      static_cast<double>(cloud.width()) * cloud.height() / kReferencePixels;
  mps.setMinInliers(static_cast<unsigned>(
      std::max(3.0, std::round(options.min_inliers * scale))));
  mps.setAngularThreshold(options.angular_threshold_deg * kDegToRad);
  mps.setDistanceThreshold(options.distance_threshold);
  mps.setMaximumCurvature(options.max_curvature);
  mps.setInputNormals(normals);
  mps.setInputCloud(points);
  std::vector<pcl::PlanarRegion<pcl::PointXYZ>,
              Eigen::aligned_allocator<pcl::PlanarRegion<pcl::PointXYZ>>>
      regions;
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers;
  pcl::PointCloud<pcl::Label>::Ptr labels(new pcl::PointCloud<pcl::Label>);
  std::vector<pcl::PointIndices> label_indices;
  std::vector<pcl::PointIndices> boundaries;
  mps.segmentAndRefine(regions, coefficients, inliers, labels, label_indices,
                       boundaries);

  // A plane's pixels are those carrying its label after the refinement
  // (which appends grown pixels to the lists without removing them from
  // their old ones, so the lists' sizes are not pixel counts).
  std::vector<size_t> pixels_of(label_indices.size(), 0);
  for (const pcl::Label& l : *labels) {
    if (l.label < pixels_of.size()) ++pixels_of[l.label];
  }
  const float min_up =
      std::cos(options.max_tilt_from_camera_up_deg * kDegToRad) - 1e-6f;
  int best = -1;
  size_t best_count = 0;
  Eigen::Vector3f best_normal;
  float best_d = 0.0f;
  for (size_t i = 0; i < coefficients.size(); ++i) {
    if (coefficients[i].values.size() != 4 || inliers[i].indices.empty()) {
      continue;
    }
    Eigen::Vector3f n(coefficients[i].values[0], coefficients[i].values[1],
                      coefficients[i].values[2]);
    float d = coefficients[i].values[3];
    if (d < 0.0f) {  // towards the camera, which is at the origin
      n = -n;
      d = -d;
    }
    if (!(-n.y() >= min_up * n.norm())) continue;
    const uint32_t label = (*labels)[inliers[i].indices[0]].label;
    if (label >= pixels_of.size()) continue;
    const size_t count = pixels_of[label];
    if (count > best_count) {
      best = static_cast<int>(label);
      best_count = count;
      best_normal = n;
      best_d = d;
    }
  }
  if (best < 0) {
    return absl::NotFoundError(
        "scene segmenter: no plane facing the camera's up direction");
  }
  cv::Mat mask(cloud.height(), cloud.width(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < cloud.height(); ++v) {
    uint8_t* m = mask.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (labels->at(u, v).label == static_cast<uint32_t>(best)) m[u] = 255;
    }
  }
  return SupportPlaneFromInliers(cloud, best_normal, best_d, mask);
}

// The candidates (points standing on the support) of a checked cloud.
absl::StatusOr<TableScene> StandingOnSupport(const OrganizedCloud& cloud,
                                             const PclSupportOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(SupportPlane plane,
                         FindPclSupportPlane(cloud, options));
  return PrepareTableScene(cloud, plane, options.table);
}

// Segment ids ordered by size, largest first; segments smaller than
// `min_pixels` dropped. `labels` holds ids in [0, count) or -1.
int RelabelBySize(int count, int min_pixels, cv::Mat& labels) {
  std::vector<int> size(count, 0);
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] >= 0) ++size[l[u]];
    }
  }
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&size](int a, int b) { return size[a] > size[b]; });
  std::vector<int> new_id(count, -1);
  int kept = 0;
  for (int id : order) {
    if (size[id] >= min_pixels) new_id[id] = kept++;
  }
  for (int v = 0; v < labels.rows; ++v) {
    int* l = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] >= 0) l[u] = new_id[l[u]];
    }
  }
  return kept;
}

using LccpPoint = pcl::PointXYZRGBA;

SceneSegmentation Lccp(const OrganizedCloud& cloud, const TableScene& table,
                       const LccpSceneOptions& options) {
  SceneSegmentation result = NoSegments(cloud);
  // An unorganized copy of the candidates; pixels[i] is point i's pixel.
  pcl::PointCloud<LccpPoint>::Ptr points(new pcl::PointCloud<LccpPoint>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  points->reserve(table.candidate_count);
  normals->reserve(table.candidate_count);
  std::vector<int> pixels;
  pixels.reserve(table.candidate_count);
  for (int v = 0; v < cloud.height(); ++v) {
    const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
    const cv::Vec3b* c =
        cloud.color.empty() ? nullptr : cloud.color.ptr<cv::Vec3b>(v);
    const cv::Vec3f* n = cloud.normals.ptr<cv::Vec3f>(v);
    const uint8_t* candidate = table.candidate.ptr<uint8_t>(v);
    for (int u = 0; u < cloud.width(); ++u) {
      if (!candidate[u]) continue;
      LccpPoint q;
      q.x = p[u][0];
      q.y = p[u][1];
      q.z = p[u][2];
      q.r = c ? c[u][0] : kGrey;
      q.g = c ? c[u][1] : kGrey;
      q.b = c ? c[u][2] : kGrey;
      q.a = 255;
      points->push_back(q);
      pixels.push_back(v * cloud.width() + u);
      // A zero normal adds nothing to its voxel's mean normal.
      const bool has_normal = std::isfinite(n[u][2]);
      normals->push_back(has_normal ? pcl::Normal(n[u][0], n[u][1], n[u][2])
                                    : pcl::Normal(0.0f, 0.0f, 0.0f));
    }
  }
  if (points->empty()) return result;

  pcl::SupervoxelClustering<LccpPoint> supervoxels(options.voxel_resolution,
                                                   options.seed_resolution);
  supervoxels.setUseSingleCameraTransform(options.use_single_camera_transform);
  supervoxels.setInputCloud(points);
  if (options.use_cloud_normals) supervoxels.setNormalCloud(normals);
  supervoxels.setColorImportance(options.color_importance);
  supervoxels.setSpatialImportance(options.spatial_importance);
  supervoxels.setNormalImportance(options.normal_importance);
  std::map<uint32_t, pcl::Supervoxel<LccpPoint>::Ptr> clusters;
  supervoxels.extract(clusters);
  if (options.refine_supervoxels) supervoxels.refineSupervoxels(2, clusters);
  if (clusters.empty()) return result;
  std::multimap<uint32_t, uint32_t> adjacency;
  supervoxels.getSupervoxelAdjacency(adjacency);

  pcl::LCCPSegmentation<LccpPoint> lccp;
  lccp.setConcavityToleranceThreshold(options.concavity_tolerance_deg);
  lccp.setSanityCheck(options.use_sanity_criterion);
  lccp.setSmoothnessCheck(true, options.voxel_resolution,
                          options.seed_resolution,
                          options.smoothness_threshold);
  lccp.setKFactor(options.k_factor);
  lccp.setInputSupervoxels(clusters, adjacency);
  lccp.setMinSegmentSize(options.min_segment_supervoxels);
  lccp.segment();
  std::map<uint32_t, uint32_t> segment_of;  // supervoxel -> LCCP segment
  lccp.getSupervoxelToSegmentMap(segment_of);

  // Supervoxel label 0 is "no supervoxel"; LCCP's segment labels become
  // dense ids.
  const pcl::PointCloud<pcl::PointXYZL>::Ptr labelled =
      supervoxels.getLabeledCloud();
  FOVEA_CHECK(labelled->size() == points->size());
  std::map<uint32_t, int> dense;
  int* out = result.labels.ptr<int>(0);  // continuous: created above
  for (size_t i = 0; i < labelled->size(); ++i) {
    const uint32_t supervoxel = (*labelled)[i].label;
    if (supervoxel == 0) continue;
    const auto segment = segment_of.find(supervoxel);
    if (segment == segment_of.end()) continue;
    const auto [it, inserted] =
        dense.emplace(segment->second, static_cast<int>(dense.size()));
    out[pixels[i]] = it->second;
  }
  result.segments = RelabelBySize(static_cast<int>(dense.size()),
                                  options.min_segment_pixels, result.labels);
  return result;
}

absl::Status NamePrefixed(const absl::Status& status,
                          absl::string_view prefix) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

}  // namespace

absl::Status Validate(const PclSupportOptions& options) {
  if (options.min_inliers < 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support.min_inliers must be >= 3, got ", options.min_inliers));
  }
  if (!(options.angular_threshold_deg > 0.0f &&
        options.angular_threshold_deg < 90.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("support.angular_threshold_deg must be in (0, 90), got ",
                     options.angular_threshold_deg));
  }
  if (!(options.distance_threshold > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("support.distance_threshold must be > 0, got ",
                     options.distance_threshold));
  }
  if (!(options.max_curvature > 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support.max_curvature must be > 0, got ", options.max_curvature));
  }
  if (!(options.max_tilt_from_camera_up_deg >= 0.0f &&
        options.max_tilt_from_camera_up_deg <= 90.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "support.max_tilt_from_camera_up_deg must be in [0, 90], got ",
        options.max_tilt_from_camera_up_deg));
  }
  return NamePrefixed(Validate(options.table), "support.");
}

absl::Status Validate(const EuclideanSceneOptions& options) {
  if (absl::Status s = Validate(options.support); !s.ok()) {
    return NamePrefixed(s, "euclidean_scene.");
  }
  return NamePrefixed(Validate(options.clusters), "euclidean_scene.");
}

absl::Status Validate(const LccpSceneOptions& options) {
  if (absl::Status s = Validate(options.support); !s.ok()) {
    return NamePrefixed(s, "lccp_scene.");
  }
  if (!(options.voxel_resolution > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lccp_scene.voxel_resolution must be > 0, got ",
                     options.voxel_resolution));
  }
  if (!(options.seed_resolution > options.voxel_resolution)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "lccp_scene.seed_resolution must exceed voxel_resolution, got ",
        options.seed_resolution));
  }
  if (!(options.color_importance >= 0.0f) ||
      !(options.spatial_importance >= 0.0f) ||
      !(options.normal_importance >= 0.0f) ||
      !(options.color_importance + options.spatial_importance +
            options.normal_importance >
        0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lccp_scene.color_importance, spatial_importance and "
                     "normal_importance must be >= 0 and not all 0, got ",
                     options.color_importance, ", ", options.spatial_importance,
                     ", ", options.normal_importance));
  }
  if (!(options.concavity_tolerance_deg >= 0.0f &&
        options.concavity_tolerance_deg <= 180.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lccp_scene.concavity_tolerance_deg must be in [0, 180], "
                     "got ",
                     options.concavity_tolerance_deg));
  }
  if (!(options.smoothness_threshold >= 0.0f &&
        options.smoothness_threshold <= 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lccp_scene.smoothness_threshold must be in [0, 1], got ",
                     options.smoothness_threshold));
  }
  if (options.min_segment_pixels < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("lccp_scene.min_segment_pixels must be >= 1, got ",
                     options.min_segment_pixels));
  }
  return absl::OkStatus();
}

absl::StatusOr<SceneSegmentation> SegmentSceneEuclidean(
    const OrganizedCloud& cloud, const EuclideanSceneOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (cloud.xyz.empty()) return SceneSegmentation{};
  FOVEA_RETURN_IF_ERROR(CheckCloud(cloud));
  if (!HasAnyPoint(cloud)) return NoSegments(cloud);
  FOVEA_ASSIGN_OR_RETURN(TableScene table,
                         StandingOnSupport(cloud, options.support));
  FOVEA_ASSIGN_OR_RETURN(
      PixelClusters clusters,
      ClusterPixels(cloud, table.candidate, options.clusters));
  SceneSegmentation result;
  result.labels = std::move(clusters.labels);
  result.segments = static_cast<int>(clusters.voxels.size());
  return result;
}

absl::StatusOr<SceneSegmentation> SegmentSceneLccp(
    const OrganizedCloud& cloud, const LccpSceneOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (cloud.xyz.empty()) return SceneSegmentation{};
  FOVEA_RETURN_IF_ERROR(CheckCloud(cloud));
  if (!HasAnyPoint(cloud)) return NoSegments(cloud);
  FOVEA_ASSIGN_OR_RETURN(TableScene table,
                         StandingOnSupport(cloud, options.support));
  return Lccp(cloud, table, options);
}

}  // namespace fovea
