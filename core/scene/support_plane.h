#ifndef FOVEA_CORE_SCENE_SUPPORT_PLANE_H_
#define FOVEA_CORE_SCENE_SUPPORT_PLANE_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

// Why a candidate surface was (or was not) taken as the support: the terms
// of its score (SupportPlaneOptions documents the weights).
struct SupportScore {
  double total = 0.0;
  int objects = 0;          // object-sized clusters standing on it, in its hull
  float area_m2 = 0.0f;     // its visible area
  float distance_m = 0.0f;  // camera to its centroid
  float tilt_deg = 0.0f;    // its normal against "up" (gravity, or estimated)
  bool under_another = false;  // a parallel surface above it covers it
};

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
  // Convex hull of the support region in plane coordinates,
  // counter-clockwise.
  std::vector<Eigen::Vector2f> hull;
  // CV_8UC1, 255 where the pixel is on the support region: the connected
  // part of the plane the objects stand on (not the same plane's other
  // surfaces beyond a gap).
  cv::Mat inliers;
  int inlier_count = 0;
  // How it was chosen: candidate surfaces considered (connected parts of the
  // planes found, or of the given plane), and the winner's score.
  int candidate_count = 0;
  SupportScore score;
  bool given = false;  // from SupportHints::plane rather than a search

  // Signed distance of p above the plane, metres.
  float Height(const Eigen::Vector3f& p) const { return normal.dot(p) + d; }
  Eigen::Vector2f ToPlane(const Eigen::Vector3f& p) const {
    return {axis_u.dot(p), axis_v.dot(p)};
  }
  // True when p's orthogonal projection lies inside the convex hull, at
  // least `margin` metres from its boundary. False for non-finite p.
  bool ProjectsInsideHull(const Eigen::Vector3f& p, float margin = 0.0f) const;
};

// What a caller may know about the support (a robot knows gravity from its
// TF tree, and often the table's plane from its map).
struct SupportHints {
  // Unit vector in the camera frame pointing down. Support planes must be
  // within SupportPlaneOptions::gravity_tolerance_deg of perpendicular to it.
  std::optional<Eigen::Vector3f> gravity;
  // The plane given outright, normal . p + d = 0 (normal of unit length,
  // either orientation): no search; its connected part with the most
  // standing on it is the support region.
  std::optional<Eigen::Vector4f> plane;  // (nx, ny, nz, d)
};

// INVALID_ARGUMENT naming the field ("gravity", "support_plane.normal",
// ...): non-finite values, a zero or non-unit vector (|v| outside 1 +-
// 0.01).
absl::Status Validate(const SupportHints& hints);

struct SupportPlaneOptions {
  // --- Sensor ---
  // A point is on a plane when within max(inlier_distance,
  // inlier_sigmas * (sigma0_m + sigma_per_z2 z^2)) of it, metres: 12 mm
  // is about 3 sigma of Kinect noise at 1.6 m (Khoshelham & Elberink 2012);
  // farther, or with a noisier sensor, the noise model's 3 sigma.
  float inlier_distance = 0.012f;
  float inlier_sigmas = 3.0f;
  float sigma0_m = 0.0f;          // set from the SensorModel
  float sigma_per_z2 = 1.43e-3f;  // 1 / m, set from the SensorModel
  // Largest angle between a point's normal and the plane normal for the
  // point to count as an inlier, degrees.
  float max_normal_angle_deg = 25.0f;

  // --- Search ---
  // RANSAC hypotheses per plane on the subsampled cloud, each a sample's
  // point and normal: 60 draws miss a plane holding 5 % of what is left
  // with probability 0.95^60 = 5 %.
  int ransac_iterations = 60;
  // Subsampling, pixels: the search works on a grid of at most
  // `grid_columns` columns (every stride-th row and column; 160 is every
  // 4th of 640, every 8th of 1280).
  int grid_columns = 160;
  // Planes are found one after the other (each one's inliers removed before
  // the next), at most this many.
  int max_planes = 6;
  // With gravity, the plane normal must be within this of "up" (-gravity),
  // degrees.
  float gravity_tolerance_deg = 15.0f;
  // Without gravity nothing is assumed about which way is up in the image
  // (the camera may be rolled or upside down): every plane in view is a
  // candidate, its up side the side the camera sees, and candidates more
  // than this from the estimated up direction (the normal of the
  // candidate that scores best as a level surface of its own) are not
  // candidates, degrees: walls are perpendicular
  // to floors and tables.
  float max_tilt_from_estimated_up_deg = 35.0f;
  // A plane needs this share of the grid's valid points to be found at all.
  float min_inlier_fraction = 0.02f;
  // A candidate surface (a connected part of a plane) needs this much
  // visible area, m^2 (a 20 x 20 cm tray; box tops smaller than that are
  // not tables).
  float min_candidate_area_m2 = 0.04f;

  // --- What stands on a candidate ---
  // What stands on a candidate: clusters of the points above it (depth-
  // connected on the grid), most of each inside its hull. A cluster is an
  // object when it rises no higher than this (higher is furniture, a wall,
  // a person), metres ...
  float max_object_height = 0.6f;
  // ... reaches down to within this of the surface (it stands on it),
  // metres ...
  float max_contact_gap = 0.05f;
  // ... is at most this wide (plane-coordinate bounding box diagonal;
  // larger is furniture), metres ...
  float max_object_size = 0.5f;
  // ... and shows at least this much area, m^2 (2 x 2 cm).
  float min_object_area_m2 = 4e-4f;

  // --- Score ---
  // total = object_weight * sum over objects of exp(-d_i / near_scale_m)
  //                         (d_i the camera's distance to object i; at most
  //                         max_counted_objects count)
  //       + area_weight * min(area / reference_area, 1)
  //       + near_weight * exp(-distance / near_scale_m)
  //       + view_weight * exp(-(off-axis angle / view_scale_deg)^2)
  //       + level_weight * cos(tilt)
  //       - under_weight * (a parallel candidate more than `under_height`
  //                         above it comes within `under_reach` of it in
  //                         the plane: it is the floor under a table)
  // What stands on a surface decides, the nearer the more (a robot looks at
  // the table it means to work on: near, and near the middle of its view);
  // size, nearness and orientation break ties (an empty table nearer than
  // the floor). under_height is above the difference between two tables
  // (up to about 0.25 m) and below a table's height over the floor (0.4 m
  // or more). Weights chosen on synthetic rooms (core/synth/room.h).

  float object_weight = 1.0f;
  int max_counted_objects = 10;
  float area_weight = 1.0f;
  float reference_area_m2 = 0.6f;
  float near_weight = 1.0f;
  float near_scale_m = 1.5f;
  float view_weight = 1.0f;
  float view_scale_deg = 25.0f;
  float level_weight = 0.5f;
  float under_weight = 3.0f;
  float under_height = 0.3f;  // metres
  float under_reach = 0.3f;   // metres

  // --- Support region ---
  // Other connected parts of the chosen plane, of at least
  // min_candidate_area_m2, join the support region when inside its hull or
  // when what lies between them and it is hidden by something in front
  // (objects standing on it split the table's image) rather than seen empty
  // (a gap to another table, the floor past the edge): at most this far
  // from the region in the plane, metres.
  float max_occlusion_gap = 0.4f;
  // ... and when their colour is within this distance of the region's
  // (CIE Lab, lightness counted half): a part of another colour is the
  // inside of something standing on it, a bowl's bottom.
  float max_join_color_distance = 20.0f;

  // Seed for the RANSAC sampler, so results are reproducible.
  uint32_t seed = 1;
};

absl::Status Validate(const SupportPlaneOptions& options);

// One candidate support surface: a connected part of a plane in view.
struct SupportCandidate {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();   // unit, to the camera
  float d = 0.0f;                                      // metres
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // metres
  SupportScore score;
  int grid_points = 0;  // of the search grid
};

struct SupportSearch {
  std::vector<SupportCandidate> candidates;  // best score first
  SupportPlane chosen;                       // made from candidates[0]
};

// Finds the support (thesis section 2.3.1, for whole rooms): several large
// planes in view by sequential RANSAC on a subsampled cloud (hypotheses from
// a point and its normal; inliers' normals must agree with the plane, their
// distances within the noise model's band), each split
// into its connected parts; every part of enough area is a candidate,
// scored by what stands on it (object-sized clusters above it inside its
// hull), its area, nearness and orientation (SupportPlaneOptions); the best
// one is refined by least squares, joined by the parts of its plane that
// objects only hide, and returned with its hull. With hints.plane, the
// candidates are that plane's parts; with hints.gravity, only planes
// perpendicular to it are candidates. NOT_FOUND when no candidate exists;
// INVALID_ARGUMENT for bad options or hints.
absl::StatusOr<SupportSearch> SearchSupport(const OrganizedCloud& cloud,
                                            const SupportPlaneOptions& options,
                                            const SupportHints& hints = {});

// SearchSupport's chosen plane.
absl::StatusOr<SupportPlane> FindSupportPlane(
    const OrganizedCloud& cloud, const SupportPlaneOptions& options,
    const SupportHints& hints = {});

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

#endif  // FOVEA_CORE_SCENE_SUPPORT_PLANE_H_
