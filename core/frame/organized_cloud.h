#ifndef FOVEA_CORE_FRAME_ORGANIZED_CLOUD_H_
#define FOVEA_CORE_FRAME_ORGANIZED_CLOUD_H_

#include <opencv2/core.hpp>

#include "absl/status/statusor.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// An organized point cloud: one entry per pixel, so (u, v) is row v,
// column u of every matrix. Owns its pixels.
//   xyz:     CV_32FC3, metres, camera frame; NaN in all three where there
//            is no depth.
//   normals: CV_32FC3, unit length, oriented towards the camera
//            (n . p < 0); NaN where no normal could be estimated.
//   color:   CV_8UC3, RGB.
struct OrganizedCloud {
  cv::Mat xyz;
  cv::Mat normals;
  cv::Mat color;
  Intrinsics intrinsics;

  int width() const { return xyz.cols; }
  int height() const { return xyz.rows; }
  bool HasPoint(int u, int v) const {
    return !std::isnan(xyz.at<cv::Vec3f>(v, u)[2]);
  }
  bool HasNormal(int u, int v) const {
    return !std::isnan(normals.at<cv::Vec3f>(v, u)[2]);
  }
};

// Normal estimation works in metres, so the same options fit every
// resolution (a pyramid level has a smaller focal length in pixels).
struct NormalOptions {
  // Half-length of the gradient baseline, metres: pixels at depth z and
  // focal length f are baseline_m * f / z. 9.5 mm is 5 px at 1 m on a
  // Kinect (f = 525 px), the scale PCL's IntegralImageNormalEstimation
  // uses with depth-dependent smoothing (Holzer et al. 2012).
  float baseline_m = 0.0095f;
  // Smallest and largest gradient half baseline, pixels.
  int min_half_window = 1;
  int max_half_window = 8;
  // Half-size of the box the cloud is smoothed with before the gradients,
  // pixels at a 525 px focal length, scaled by f / 525 (2: a 5x5 box on a
  // Kinect frame, averaging its disparity quantisation; 0 at level 2).
  int smoothing_half_window = 2;
  // Depth change above which a neighbour is not on the same surface,
  // as a fraction of depth per pixel of baseline (PCL's
  // max_depth_change_factor).
  float max_depth_change_factor = 0.02f;
};

absl::Status Validate(const NormalOptions& options);

// Back-projects the frame and estimates normals. Normals are the cross
// product of the horizontal and vertical 3D gradients (central differences
// over a depth-adaptive baseline) of the box-smoothed point cloud,
// smoothing over valid points only (the "average 3D gradient" method of
// Holzer et al. 2012). Chosen
// over PCA of k nearest neighbours because it is O(1) per pixel on an
// organized cloud and keeps the 640x480 budget (thesis section 2.3 uses
// integral-image normals for the same reason); the depth-adaptive window
// tames Kinect noise, which grows with z^2.
absl::StatusOr<OrganizedCloud> BuildOrganizedCloud(
    const RgbdFrame& frame, const NormalOptions& options);

// Back-projection only (normals left as NaN). A sensor's regular dropouts
// (every other or every 4th column or row missing, as decimating and
// interlacing drivers give) are bridged: when runs of one or two pixels
// without depth between two points on one surface (depth changing by at
// most 5 z / f per pixel between them: a surface seen at up to 79 degrees
// from its normal) would add a tenth of the frame's points or more, each
// such run, along the rows and then the columns, is filled with the plane
// through its two ends (each point on its pixel's ray). Ordinary frames,
// whose thin gaps (at edges, on dark objects) add well under 1 %, are
// back-projected exactly as sent.
OrganizedCloud BackProject(const RgbdFrame& frame);

// Estimates `cloud.normals` from `cloud.xyz` in place.
void EstimateNormals(const NormalOptions& options, OrganizedCloud& cloud);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_ORGANIZED_CLOUD_H_
