#ifndef FOVEA_CORE_FRAME_RGBD_FRAME_H_
#define FOVEA_CORE_FRAME_RGBD_FRAME_H_

#include <opencv2/core.hpp>

namespace fovea {

// Pinhole intrinsics in pixels. Depth is registered to colour, so both images
// share them. A pixel (u, v) with depth z is the point
// ((u - cx) z / fx, (v - cy) z / fy, z) in the camera frame (x right, y down,
// z forward, metres).
struct Intrinsics {
  double fx = 0.0;  // focal length, pixels, > 0
  double fy = 0.0;  // focal length, pixels, > 0
  double cx = 0.0;  // principal point column, pixels
  double cy = 0.0;  // principal point row, pixels
};

// The Kinect v1 intrinsics of the OSD data set (shared/data/README.md).
inline constexpr Intrinsics kKinectV1Intrinsics{525.0, 525.0, 319.5, 239.5};

// A decoded RGB-D frame. Owns its pixels; move it, do not copy it.
//   color: CV_8UC3, RGB order, height x width.
//   depth: CV_32FC1, metres, NaN where the sensor has no data; same size.
struct RgbdFrame {
  cv::Mat color;
  cv::Mat depth;
  Intrinsics intrinsics;

  int width() const { return depth.cols; }
  int height() const { return depth.rows; }
};

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_RGBD_FRAME_H_
