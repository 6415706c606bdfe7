#ifndef FOVEA_CORE_SEGMENTATION_INC_NEIGHBOURS_H_
#define FOVEA_CORE_SEGMENTATION_INC_NEIGHBOURS_H_

// INC's neighbours beyond the surfaces' shared borders, added while the
// scene is built (inc.cc's BuildIncScene). Internal to core/segmentation.

#include <opencv2/core.hpp>

#include "core/segmentation/inc.h"

namespace fovea {

// Adds to scene.neighbours the pairs of object surfaces at most
// body_join.gap_px apart in `labels` (-1: none or support) within `box`,
// across pixels of no object surface, that are not neighbours and lie on
// one body.
void AddGapNeighbours(const cv::Mat& labels, const cv::Rect& box, float fx,
                      const IncOptions& options, IncScene& scene);

// IncOptions::AcrossOccluder: scans the rows and columns of `box` for two
// planar surfaces separated only by nearer points, each side's pixel on
// the other's plane; pairs met on enough lines, upright, parallel and alike
// in colour become neighbours (scene.neighbours, scene.across_occluder).
// Needs scene.relations, xyz, intrinsics and points.
void AddOccludedNeighbours(const cv::Mat& labels, const cv::Rect& box,
                           const IncOptions& options, IncScene& scene);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_INC_NEIGHBOURS_H_
