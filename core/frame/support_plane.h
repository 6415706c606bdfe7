#ifndef FOVEA_CORE_FRAME_SUPPORT_PLANE_H_
#define FOVEA_CORE_FRAME_SUPPORT_PLANE_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

// The plane the objects stand on (thesis section 2.3.1), in Hesse normal
// form normal . p + d = 0 with `normal` of unit length and pointing to the
// side the camera is on, so objects on the table have positive height.
struct SupportPlane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  float d = 0.0f;  // metres
  // Orthonormal axes spanning the plane; (axis_u, axis_v, normal) is
  // right-handed. Plane coordinates of p: (axis_u . p, axis_v . p).
  Eigen::Vector3f axis_u = Eigen::Vector3f::UnitX();
  Eigen::Vector3f axis_v = Eigen::Vector3f::UnitY();
  // Convex hull of the inliers in plane coordinates, counter-clockwise.
  std::vector<Eigen::Vector2f> hull;
  cv::Mat inliers;  // CV_8UC1, 255 where the pixel is on the plane
  int inlier_count = 0;

  // Signed distance of p above the plane, metres.
  float Height(const Eigen::Vector3f& p) const { return normal.dot(p) + d; }
  Eigen::Vector2f ToPlane(const Eigen::Vector3f& p) const {
    return {axis_u.dot(p), axis_v.dot(p)};
  }
  // True when p's orthogonal projection lies inside the convex hull, at
  // least `margin` metres from its boundary. False for non-finite p.
  bool ProjectsInsideHull(const Eigen::Vector3f& p, float margin = 0.0f) const;
};

struct SupportPlaneOptions {
  // Inlier distance for RANSAC and refinement, metres (about 3 sigma of
  // Kinect noise at 1.2 m, Khoshelham & Elberink 2012).
  float inlier_distance = 0.012f;
  // Largest angle between a point's normal and the plane normal for the
  // point to count as an inlier, degrees.
  float max_normal_angle_deg = 25.0f;
  // RANSAC iterations on the subsampled cloud.
  int ransac_iterations = 200;
  // Subsampling stride for RANSAC, pixels (every stride-th row and column).
  int subsample_stride = 4;
  // Candidate planes must face the camera's "up": the angle between the
  // plane normal and the camera's -y axis (up in the image) is at most
  // this, degrees. Rejects walls; 90 disables the test.
  float max_tilt_from_camera_up_deg = 75.0f;
  // Smallest plane, as a fraction of the valid pixels sampled.
  float min_inlier_fraction = 0.05f;
  // Seed for the RANSAC sampler, so results are reproducible.
  uint32_t seed = 1;
};

absl::Status Validate(const SupportPlaneOptions& options);

// Finds the support plane: RANSAC on a subsampled cloud (normals must
// agree with the plane), refined by least squares on all inliers, then
// the largest 8-connected component of inlier pixels (so coplanar
// surfaces elsewhere do not widen the hull) and its convex hull.
// Among candidate planes, the largest horizontal-looking one wins.
// NOT_FOUND when no plane with enough support exists.
absl::StatusOr<SupportPlane> FindSupportPlane(
    const OrganizedCloud& cloud, const SupportPlaneOptions& options);

// A support plane found by other means (e.g. PCL's organized multi-plane
// segmentation, core/baseline/scene_segmenters.h) made whole: `normal`
// (need not be unit length) and `d` are normalised and turned towards the
// camera, the axes set as FindSupportPlane sets them, and the convex hull
// taken of `inliers` (CV_8UC1 of the cloud's size, non-zero = on the plane;
// kept as the plane's `inliers`). INVALID_ARGUMENT for a zero normal or a
// mask of another size; NOT_FOUND when the inliers have no 2D extent.
absl::StatusOr<SupportPlane> SupportPlaneFromInliers(
    const OrganizedCloud& cloud, const Eigen::Vector3f& normal, float d,
    const cv::Mat& inliers);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_SUPPORT_PLANE_H_
