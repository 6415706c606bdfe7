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
//              the noise-dependent minimum and its projection inside the
//              table's convex hull (thesis section 2.3.1), `hull_margin` from
//              its boundary. Only these get saliency.
//   region:    CV_8UC1, 255 on the support region (SupportPlane::inliers)
//              and on what may stand on it: points below max_object_height
//              whose projection lies inside the hull. Everything else
//              (floor, walls, other tables, chairs beside it) is outside
//              the scene segmentation works on.
struct TableScene {
  cv::Mat height;
  cv::Mat candidate;
  int candidate_count = 0;
  cv::Mat region;
};

struct TableSceneOptions {
  // Points closer to the plane than max(min_object_height,
  // min_height_sigmas * (sigma0_m + sigma_per_z2 z^2)) are table, metres:
  // 1 cm is above the plane fit's noise at Kinect range (thesis section
  // 2.3.1); farther, or with a noisier sensor, the noise model's 3 sigma.
  float min_object_height = 0.01f;
  float min_height_sigmas = 3.0f;
  float sigma0_m = 0.0f;          // set from the SensorModel
  float sigma_per_z2 = 1.43e-3f;  // 1 / m, set from the SensorModel
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
