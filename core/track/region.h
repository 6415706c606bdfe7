#ifndef FOVEA_CORE_TRACK_REGION_H_
#define FOVEA_CORE_TRACK_REGION_H_

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/frame/rgbd_frame.h"
#include "core/pipeline/segment.h"

namespace fovea {

// The part of a frame that is segmented again when only some of it changed
// and the camera is still (TrackerOptions::reuse_regions): the objects
// outside it are kept as they were.

struct RegionOptions {
  // Pixels added around the changed pixels' bounding box and around each
  // held object's box taken in, at a 640-pixel-wide frame (scaled with the
  // frame's width).
  int margin_px = 16;
  // No smaller than this, at a 640-pixel-wide frame (the pipeline's
  // smallest processing width and its 4:3 height).
  cv::Size min_size{160, 120};
  // A region over this fraction of the frame's pixels is not worth
  // cutting out: the whole frame is segmented.
  double max_fraction = 0.5;
};

// The region to segment again: the bounding box of `changed` (CV_8UC1,
// non-zero where changed) grown by the margin, then grown until every box
// of `held` (the objects of the last frame) it overlaps lies inside it, so
// that none of them is cut at its border; at least min_size, within the
// frame. nullopt when nothing changed or the region would be larger than
// max_fraction of the frame.
std::optional<cv::Rect> RegionToSegment(const cv::Mat& changed,
                                        const std::vector<cv::Rect>& held,
                                        const RegionOptions& options);

// `region` of `frame` as a frame of its own: its pixels (copied) and the
// intrinsics of the cut-out (the principal point moved by its corner).
RgbdFrame CropFrame(const RgbdFrame& frame, const cv::Rect& region);

// Whether `box` (pixels of a crop of `region`) reaches a border of the
// crop that is not a border of the frame of `frame_size`: an object there
// may go on outside the crop.
bool ReachesInnerBorder(const cv::Rect& box, const cv::Rect& region,
                        cv::Size frame_size);

// An object segmented in the crop of `region` as an object of the whole
// frame (`frame_size`): its mask, box and seed moved by the region's
// corner; its centroid, extent, geometry and points are in the camera frame
// and stay. Its point indices, which are the crop's, are dropped.
void ObjectToFrame(const cv::Rect& region, cv::Size frame_size,
                   SegmentedObject& object);

}  // namespace fovea

#endif  // FOVEA_CORE_TRACK_REGION_H_
