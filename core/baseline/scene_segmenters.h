#ifndef FOVEA_CORE_BASELINE_SCENE_SEGMENTERS_H_
#define FOVEA_CORE_BASELINE_SCENE_SEGMENTERS_H_

#include <cstdint>
#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/baseline/pcl_clusters.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/table_scene.h"

namespace fovea {

// Two whole-scene segmenters built from PCL, the peers our attention-driven
// segmentation (thesis chapter 3) is compared with side by side. Unlike
// COS and EBS they need no attention point: they cut the whole table scene
// into object hypotheses at once.
//
// Both share the first step: PCL's organized multi-plane segmentation
// (pcl::OrganizedMultiPlaneSegmentation on the cloud's own normals) finds
// the planes; the largest one facing the camera's up is the support, and
// what stands on it (TableScene's candidates: above the plane and inside
// its convex hull) is segmented. So the peers differ only in how they cut
// the objects apart.

// Every object hypothesis of a whole scene.
struct SceneSegmentation {
  // CV_32SC1 of the cloud's size: segment id in [0, segments), 0 the
  // largest segment; -1 for none (no depth, the support plane, off the
  // table, or in a segment too small to keep).
  cv::Mat labels;
  int segments = 0;
};

// The support-plane step both peers share.
struct PclSupportOptions {
  // Smallest plane, pixels (PCL's default is 1000; its organized
  // segmentation demo uses 10000 on 640x480 frames). Scaled by the
  // cloud's pixel count / (640 * 480), so it fits every resolution.
  int min_inliers = 5000;
  // Largest angle between neighbouring normals within a plane, degrees
  // (PCL's default).
  float angular_threshold_deg = 3.0f;
  // Largest difference of neighbouring points' plane offsets, metres at
  // 1 m, growing with depth squared (PCL's default, depth dependent).
  float distance_threshold = 0.02f;
  // Largest surface variation (smallest eigenvalue / sum) of a plane's
  // points (PCL's default).
  float max_curvature = 0.001f;
  // The support must face the camera's "up" (-y): largest angle between
  // them, degrees (as SupportPlaneOptions).
  float max_tilt_from_camera_up_deg = 75.0f;
  // What stands on the support.
  TableSceneOptions table;
};

absl::Status Validate(const PclSupportOptions& options);

// "pcl-euclidean": what a robotics engineer reaches for in PCL. The points
// standing on the support are clustered with pcl::EuclideanClusterExtraction
// (ClusterPixels, shared with the PclClusters attention peer). Objects that
// touch, or stand closer than the tolerance, become one segment: the peer's
// known weakness.
struct EuclideanSceneOptions {
  PclSupportOptions support;
  // Euclidean clustering: 2 cm tolerance (PCL's tutorial), 5 mm voxels,
  // clusters of fewer than 30 voxels (about 7.5 cm^2 of surface) dropped.
  PclClustersOptions clusters;
};

absl::Status Validate(const EuclideanSceneOptions& options);

// Segments `cloud` (normals required: the plane step uses them). Segments
// are ordered largest first (in voxels). A cloud without points (empty, or
// NaN everywhere) gives zero segments and labels all -1 (0x0 for an empty
// cloud); a cloud with points but no plane facing up is NOT_FOUND;
// INVALID_ARGUMENT names the bad option or matrix.
absl::StatusOr<SceneSegmentation> SegmentSceneEuclidean(
    const OrganizedCloud& cloud, const EuclideanSceneOptions& options);

// "pcl-lccp": supervoxels (Papon et al. 2013) and locally convex connected
// patches (Stein et al. 2014, pcl::LCCPSegmentation) of the points standing
// on the support. Supervoxels work on an unorganized copy of those points;
// each pixel takes the segment of its point's voxel. Defaults are those of
// PCL's example_lccp_segmentation for Kinect-like data with its -nonormals,
// -ec and -smooth 3 switches (chosen on the OSD learning scenes; see the
// fields).
struct LccpSceneOptions {
  PclSupportOptions support;
  // Supervoxel voxel size, metres.
  float voxel_resolution = 0.0075f;
  // Supervoxel seed spacing, metres.
  float seed_resolution = 0.03f;
  // Weights of colour, spatial and normal distance in the supervoxels'
  // clustering, >= 0 (0 ignores colour, as the example does).
  float color_importance = 0.0f;
  float spatial_importance = 1.0f;
  float normal_importance = 4.0f;
  // Give the supervoxels the cloud's normals (zero where it has none), as
  // the example does when its input has normals; false (the example's
  // -nonormals): PCL estimates each voxel's normal from its neighbours,
  // which scored higher on the OSD learning scenes (F 0.925 against 0.918).
  bool use_cloud_normals = false;
  // Voxelize in PCL's depth-dependent "single camera" space (the example's
  // -tvoxel switch, off by default).
  bool use_single_camera_transform = false;
  // Refine the supervoxels (two more clustering passes; example: off).
  bool refine_supervoxels = false;
  // Concave edges flatter than this count as convex, degrees in [0, 180].
  float concavity_tolerance_deg = 10.0f;
  // Invalidate steps between parallel supervoxels further apart than
  // smoothness_threshold * voxel_resolution; in [0, 1], 1 = no check.
  float smoothness_threshold = 0.1f;
  // k of the extended convexity test: an edge stays convex only with k
  // common neighbours convexly connected to both (0: off, 1: the example's
  // -ec). OSD learning scenes: F 0.925 with 1 against 0.901 with 0; it is
  // also what cuts touching boxes apart at a concave junction (see
  // tests/core/baseline/scene_segmenters_test.cc).
  uint32_t k_factor = 1;
  // Sanity criterion: invalidate singular connections (example: off).
  bool use_sanity_criterion = false;
  // LCCP merges segments of fewer supervoxels into their largest
  // neighbour (the example's -smooth; 0 = off; 3 took OSD's cylinders from
  // F 0.82 to 0.86 with k_factor 1).
  uint32_t min_segment_supervoxels = 3;
  // Segments of fewer pixels are dropped (labels -1), >= 1.
  int min_segment_pixels = 100;
};

absl::Status Validate(const LccpSceneOptions& options);

// Segments `cloud` (normals required for the plane step; colour used when
// color_importance > 0, grey when the cloud has none). Segments are ordered
// largest first (in pixels). Empty input and errors as
// SegmentSceneEuclidean.
absl::StatusOr<SceneSegmentation> SegmentSceneLccp(
    const OrganizedCloud& cloud, const LccpSceneOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_BASELINE_SCENE_SEGMENTERS_H_
