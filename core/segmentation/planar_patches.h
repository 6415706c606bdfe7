#ifndef FOVEA_CORE_SEGMENTATION_PLANAR_PATCHES_H_
#define FOVEA_CORE_SEGMENTATION_PLANAR_PATCHES_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

struct PlanarPatchOptions {
  // A point joins a patch when its distance to the patch's plane is at most
  // this plus `distance_per_m2` * z^2, metres (the Kinect's axial noise
  // grows with z^2, Khoshelham & Elberink 2012: 1.4 mm/m^2 sigma; 5 mm at
  // 1 m covers three sigma plus normal smoothing).
  float max_plane_distance = 0.004f;
  float distance_per_m2 = 0.0015f;
  // ... and its normal is within this angle of the plane's, degrees.
  float max_normal_angle_deg = 20.0f;
  // ... and its depth differs from the neighbour it is reached from by at
  // most this fraction of depth (no growing across occluding edges).
  float max_depth_step_fraction = 0.02f;
  // The plane is refitted (least squares) each time the patch has grown by
  // this factor since the last fit; 0 keeps the seed's plane.
  float refit_growth = 2.0f;
  // Patches with fewer points are noise (label -1), pixels.
  int min_points = 30;
};

absl::Status Validate(const PlanarPatchOptions& options);

struct PlanarPatch {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, to camera
  float d = 0.0f;                                    // n . p + d = 0
  // Of the points grown into the patch (before the leftovers joined).
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // metres
  int points = 0;                                      // pixels
  cv::Rect box;                                        // image bounding box
};

struct PlanarPatches {
  // CV_32SC1 of the cloud's size: the patch index, -1 for noise, no depth
  // or outside the mask.
  cv::Mat labels;
  std::vector<PlanarPatch> patches;
  // Pairs (a, b), a < b, of patches with 4-adjacent pixels; sorted, unique.
  std::vector<std::pair<int, int>> adjacency;
};

// Planar patches by "clustering normals" (thesis section 3.2.2): repeatedly
// take the unassigned point of lowest curvature as a seed, fit its plane
// (its point and normal), and grow over 4-neighbours while they fit the
// plane (distance and normal angle above) and no depth step separates
// them, refitting the plane as the patch grows; until every point belongs
// to a patch or is noise. Then the points left over (near folds, where
// normals are smoothed across the fold) join a 4-neighbouring patch whose
// plane they lie on, breadth first from the patches. Curvature is 1 - |n . m|,
// m the mean normal of the 3 x 3 neighbourhood. `mask` (CV_8UC1, non-zero =
// use; empty = all points with a normal) limits the points. Work is linear in
// the pixels.
//
// `support` (CV_8UC1, non-zero on the support plane's inliers; empty =
// none): its points are not grown but taken as they are, each 4-connected
// part of them one patch (its plane fitted to its points), before the
// leftovers join. On a table scene that is most of the points (85 % of the
// labelled ones in the OSD scenes), the support's patches being what the
// growth would make of them anyway, up to their rims.
//
// Errors: invalid options, a mask or support of another size or type.
absl::StatusOr<PlanarPatches> FindPlanarPatches(
    const OrganizedCloud& cloud, const cv::Mat& mask,
    const PlanarPatchOptions& options, const cv::Mat& support = cv::Mat());

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_PLANAR_PATCHES_H_
