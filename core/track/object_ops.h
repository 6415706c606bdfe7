#ifndef FOVEA_CORE_TRACK_OBJECT_OPS_H_
#define FOVEA_CORE_TRACK_OBJECT_OPS_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/pipeline/segment.h"

namespace fovea {

// What the tracker does to one frame's objects (tracker.h): whether two
// touch, joining pieces into one, an object's colour, the common motion
// of many.

// The median of each coordinate of `v` (zero when empty).
Eigen::Vector3f CoordinateMedian(std::vector<Eigen::Vector3f> v);

// Whether masks `a` and `b` (CV_8UC1, same size; `a_box` and `b_box` their
// bounding boxes) touch: `a` grown by `radius` pixels overlaps `b`.
bool Touch(const cv::Mat& a, const cv::Rect& a_box, const cv::Mat& b,
           const cv::Rect& b_box, int radius);

// Adds `piece` to `into`: the union of the masks, the box and area of the
// union, the area-weighted centroid, the larger extent, both point sets;
// the geometry is dropped (the pieces' boxes are not the whole's).
void Join(const SegmentedObject& piece, SegmentedObject& into);

// The colour of `object` in `color` (RGB, CV_8UC3, the mask's size): a
// 4 x 4 x 4 histogram (CV_32F) of its mask's pixels, to compare with
// cv::compareHist; empty without colour or pixels.
cv::Mat Appearance(const cv::Mat& color, const SegmentedObject& object);

}  // namespace fovea

#endif  // FOVEA_CORE_TRACK_OBJECT_OPS_H_
