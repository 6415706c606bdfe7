#ifndef FOVEA_CORE_SCENE_TABLE_SCENE_H_
#define FOVEA_CORE_SCENE_TABLE_SCENE_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"

namespace fovea {

// What the 3D saliency operators share: each point's height above the
// support plane and which points may be salient at all.
//   height:    CV_32FC1, metres above the plane; NaN where there is no point.
//   candidate: CV_8UC1, 255 where a point stands on the table: height above
//              the noise-dependent minimum and its projection inside the
//              table's convex hull (thesis section 2.3.1), `hull_margin` from
//              its boundary. Only these get saliency.
//   standing:  CV_8UC1, 255 where a point stands on the table as a
//              candidate does, but with no margin inside the hull (the
//              candidates' superset); and on what rests on the table
//              beyond the hull (TableSceneOptions::rest_beyond_hull_m),
//              which is a candidate too.
//   region:    CV_8UC1, 255 on the support region (SupportPlane::inliers)
//              and on what may stand on it: points below max_object_height
//              whose projection lies inside the hull, and what rests on
//              the table beyond it (as standing). Everything else
//              (floor, walls, other tables, chairs beside it) is outside
//              the scene segmentation works on.
//   structures: large vertical planes that extend beyond what can stand on
//              the table (walls, cabinet sides, whiteboards rising at its
//              edge); their points are in neither mask, even where noise
//              projects them inside the hull.
struct TableScene {
  cv::Mat height;
  cv::Mat candidate;
  int candidate_count = 0;
  cv::Mat standing;
  cv::Mat region;
  struct Plane {
    Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit
    float d = 0.0f;                                     // metres
  };
  std::vector<Plane> structures;
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
  // Structures: vertical planes (normal within structure_tolerance_deg of
  // perpendicular to the support's) of which at least structure_min_area_m2
  // lies beyond the table (outside its hull, above max_object_height or
  // below the table): 0.15 m^2 is larger than the face of any box a robot
  // handles on a table, and the part beyond means it is not on the table.
  // At most structure_max_planes are found (0 disables).
  float structure_tolerance_deg = 15.0f;
  float structure_min_area_m2 = 0.15f;
  int structure_max_planes = 3;
  // What rests on the table beyond the hull of the table the camera sees:
  // where books, trays and objects cover most of a table, or the table's
  // far end is cut off (OSD's crop), the visible top is a few fragments
  // and the objects behind them project outside their hull. Points above
  // the table (as candidates, within max_object_height, on no structure)
  // outside the hull but at most this far from it in the plane join the
  // scene (region, standing and candidate) when they are connected in the
  // image, without a jump in depth, to candidates (hull_margin inside it,
  // so not through a wall rising at the table's edge): the pile is one
  // scene, whatever of the table shows, metres (a
  // book's width and a half; 0 disables).
  float rest_beyond_hull_m = 0.35f;
  // ... and so do parts (connected without a jump in depth, within that
  // reach, followed through their feet at the table's level) that touch
  // nothing in the scene but stand on the table where the camera does not
  // see it: their lowest point within 2 cm of the height where the table
  // ends, at most max_resting_size_m across in the plane (the support
  // search's object size: larger is furniture, a wall above the table's
  // back edge), bordering no visible table top (what does stands behind
  // the table's edge or on another table) and not going on beyond the
  // reach or above max_object_height. Parts that the candidates reach are
  // held to the same size, and to 60 pixels at 640 x 480 at least (the
  // specks of a wall that its depth noise carries inside the hull).
  bool rest_on_hidden_table = true;
  float max_resting_size_m = 0.5f;
};

absl::Status Validate(const TableSceneOptions& options);

TableScene PrepareTableScene(const OrganizedCloud& cloud,
                             const SupportPlane& plane,
                             const TableSceneOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SCENE_TABLE_SCENE_H_
