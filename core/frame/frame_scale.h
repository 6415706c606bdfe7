#ifndef FOVEA_CORE_FRAME_FRAME_SCALE_H_
#define FOVEA_CORE_FRAME_FRAME_SCALE_H_

#include <opencv2/core.hpp>

#include "core/frame/rgbd_frame.h"

namespace fovea {

// Frames wider than the processing width are processed reduced, so that a
// 1280x720 frame costs about what a 640x480 one does; what comes back
// (points, masks, maps) is mapped to the frame as sent. Pixel (u, v) of the
// reduced frame covers the input pixels whose centres map into it: input
// centre x maps to (x + 0.5) * factor - 0.5.
struct FrameScale {
  double factor = 1.0;  // reduced / input, (0, 1]
  cv::Size input;       // the frame as sent

  bool reduced() const { return factor < 1.0; }
  // The reduced pixel holding input pixel p, and the input pixel at the
  // centre of reduced pixel q; both clamped to the image.
  cv::Point ToProcessing(cv::Point p) const;
  cv::Point ToInput(cv::Point q) const;
  // A reduced CV_8UC1 mask at the input size (each input pixel takes the
  // value of the reduced pixel holding it).
  cv::Mat MaskToInput(const cv::Mat& mask) const;
  // A reduced CV_32FC1 map at the input size (bilinear).
  cv::Mat MapToInput(const cv::Mat& map) const;
};

// The default processing width, pixels: a Kinect's and most RGB-D cameras'
// native depth width, where every pixel threshold of the pipeline was set.
inline constexpr int kDefaultProcessingWidth = 640;

// The frame at most `processing_width` wide: colour by area averaging,
// depth by the input pixel nearest each reduced pixel's centre (averaging
// depths across an edge would invent points between the surfaces), the
// intrinsics scaled to match. A frame no wider is returned as is (sharing
// its pixels). Precondition: processing_width > 0.
struct ReducedFrame {
  RgbdFrame frame;
  FrameScale scale;
};
ReducedFrame ReduceForProcessing(const RgbdFrame& frame, int processing_width);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_FRAME_SCALE_H_
