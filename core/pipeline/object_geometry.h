#ifndef FOVEA_CORE_PIPELINE_OBJECT_GEOMETRY_H_
#define FOVEA_CORE_PIPELINE_OBJECT_GEOMETRY_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"

namespace fovea {

// What a grasp planner needs of an object besides its mask: a box standing
// on the support, in the camera frame and in a frame on the support.

struct BoxFitOptions {
  // The lowest and highest `trim_percent` % of the points' heights above
  // the support are left out of the box (flying pixels at silhouettes,
  // depth noise), percent, [0, 25).
  float trim_percent = 1.0f;
  // A box whose lowest kept point is at most this far above the support
  // (or below it) stands on it: its base goes down to the plane (a
  // camera rarely sees an object's last centimetre above the table, and
  // the sensor drops it where it meets the table), metres, >= 0. Higher,
  // the object rests on another one and the base is its lowest point.
  float rest_on_support_m = 0.02f;
};

// INVALID_ARGUMENT naming the field.
absl::Status Validate(const BoxFitOptions& options);

// A box: its centre, the rotation taking the box's axes to the frame's
// (box x along its length, y along its width, z up the support normal) and
// its size along those axes, metres (size.x() >= size.y()).
struct OrientedBox {
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  Eigen::Vector3f size = Eigen::Vector3f::Zero();
};

struct ObjectGeometry {
  // In the camera frame (x right, y down, z forward), metres.
  OrientedBox box;
  // The support frame, as a pose in the camera frame: origin on the
  // support plane below the box's centre, z along the support normal (up,
  // towards the camera's side), x along SupportPlane::axis_u, y along
  // axis_v.
  Eigen::Vector3f support_origin = Eigen::Vector3f::Zero();
  Eigen::Quaternionf support_orientation = Eigen::Quaternionf::Identity();
  // The same box in the support frame: centre (0, 0, base + height / 2),
  // rotated about z only (the box's yaw on the support).
  OrientedBox box_in_support;
  float height_above_support = 0.0f;  // the box's top above the plane, m
  float footprint_area_m2 = 0.0f;     // its base, size.x() * size.y()
};

// The smallest box, on the footprint, holding the object's points: its
// vertical axis along the support normal; its footprint the minimum-area
// rectangle of the points projected onto the plane; its top the highest
// point, its base the plane or the lowest point (BoxFitOptions), both
// after trimming. Points are metres in the camera frame; non-finite ones
// are skipped. Errors: invalid options; FAILED_PRECONDITION when fewer
// than 3 finite points are left or the plane has no axes.
absl::StatusOr<ObjectGeometry> FitSupportAlignedBox(
    const std::vector<Eigen::Vector3f>& points, const SupportPlane& plane,
    const BoxFitOptions& options = {});

// The mask's points with depth (CV_8UC1 mask of the cloud's size, non-zero
// on the object), in raster order; only pixels in `within` (empty: all).
std::vector<Eigen::Vector3f> MaskPoints(const OrganizedCloud& cloud,
                                        const cv::Mat& mask,
                                        const cv::Rect& within = cv::Rect());

// At most `max_points` of `count` items, evenly spread and in order: the
// positions floor(i * count / max_points); all of them when max_points is
// 0 or count <= max_points.
std::vector<int> EvenSample(int count, int max_points);

// The pixels of a mask (CV_8UC1, non-zero on the object) as organized
// indices v * width + u, in raster order, evenly sampled to at most
// `max_points` (0: all).
std::vector<int> MaskIndices(const cv::Mat& mask, int max_points);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_OBJECT_GEOMETRY_H_
