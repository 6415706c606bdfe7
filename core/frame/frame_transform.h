#ifndef FOVEA_CORE_FRAME_FRAME_TRANSFORM_H_
#define FOVEA_CORE_FRAME_FRAME_TRANSFORM_H_

#include <opencv2/core.hpp>

#include "core/frame/osd_pcd.h"
#include "core/frame/rgbd_frame.h"

namespace fovea {

// Exact pixel transforms of a frame, with the intrinsics to match: the same
// scene as a camera rolled about its optical axis, or one of half the
// resolution, would see it. What evaluations run to check that results do
// not depend on the camera's roll or resolution.

// The frame rotated clockwise in the image by `quarter_turns` x 90 degrees
// (any integer; taken mod 4): every pixel moves, none is resampled. A
// quarter turn maps pixel (u, v) of a W x H frame to (H - 1 - v, u) of an
// H x W one, with fx' = fy, fy' = fx, cx' = H - 1 - cy, cy' = cx, so that
// each pixel's 3D point is the original one rotated about the optical axis
// ((x, y, z) -> (-y, x, z)). Two turns: (W - 1 - u, H - 1 - v).
RgbdFrame RotateFrame(const RgbdFrame& frame, int quarter_turns);

// Any per-pixel image (labels, a mask) rotated as RotateFrame rotates the
// frame.
cv::Mat RotateImage(const cv::Mat& image, int quarter_turns);

// The frame at half its resolution (W / 2 x H / 2, rounded down): pixel
// (u, v) takes depth from input pixel (2u, 2v), so every depth is a
// measured one and its 3D point is unchanged (fx' = fx / 2, cx' = cx / 2,
// likewise y); colour is the mean of the 2 x 2 block starting there.
RgbdFrame HalveFrame(const RgbdFrame& frame);

// Per-pixel labels sampled as HalveFrame samples depth: (2u, 2v).
cv::Mat HalveLabels(const cv::Mat& labels);

// A labelled frame rotated or halved, labels with it; the name gets
// "-rot90" / "-rot180" / "-rot270" or "-half" appended.
LabelledFrame RotateLabelledFrame(const LabelledFrame& frame,
                                  int quarter_turns);
LabelledFrame HalveLabelledFrame(const LabelledFrame& frame);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_FRAME_TRANSFORM_H_
