#ifndef FOVEA_CORE_FRAME_TABLE_SCENE_H_
#define FOVEA_CORE_FRAME_TABLE_SCENE_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/support_plane.h"

namespace fovea {

// What the 3D saliency operators share: each point's height above the
// support plane and which points may be salient at all.
//   height:    CV_32FC1, metres above the plane; NaN where there is no point.
//   candidate: CV_8UC1, 255 where a point stands on the table: height above
//              `min_object_height` and its projection inside the table's
//              convex hull (thesis section 2.3.1), `hull_margin` from its
//              boundary. Only these get saliency.
struct TableScene {
  cv::Mat height;
  cv::Mat candidate;
  int candidate_count = 0;
};

struct TableSceneOptions {
  // Points closer to the plane than this are table, metres (above the
  // plane fit's noise at Kinect range, thesis section 2.3.1).
  float min_object_height = 0.01f;
  // Points higher than this above the plane are not on the table (people,
  // shelves), metres.
  float max_object_height = 0.6f;
  // A candidate's projection must lie this far inside the table's convex
  // hull, metres. Walls and shelves rising at the table's edge project onto
  // the hull's boundary (within sensor noise); objects on the table keep
  // all but their outermost 2 cm.
  float hull_margin = 0.02f;
};

absl::Status Validate(const TableSceneOptions& options);

TableScene PrepareTableScene(const OrganizedCloud& cloud,
                             const SupportPlane& plane,
                             const TableSceneOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_TABLE_SCENE_H_
