#ifndef FOVEA_CORE_FRAME_SURFACE_EDGES_H_
#define FOVEA_CORE_FRAME_SURFACE_EDGES_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

struct SurfaceEdgeOptions {
  // Each pixel is compared with the neighbours this many pixels away (at a
  // 525 px focal length; scaled by f / 525, at least 1). 6 px is 11 mm at
  // 1 m, wider than the normals' own smoothing (NormalOptions::baseline_m),
  // so a fold shows as a difference of the two faces' normals. On the 45
  // OSD learn scenes 6-8 px split touching objects best; 2-4 px see only
  // part of a smoothed fold, 10 px starts cutting small objects apart.
  int radius_px = 6;
  // Occluding edge: a neighbour whose depth differs by more than this
  // fraction of the nearer depth (0.025: 2.5 cm at 1 m, about four times
  // the Kinect's depth noise there, Khoshelham & Elberink 2012). 0 disables.
  float depth_jump_fraction = 0.025f;
  // Concave crease: a neighbour q of p with
  // (n_q - n_p) . (q - p) / |q - p| < -concave_curvature, i.e. the normals
  // converge as on the inside of a fold (where an object stands on the
  // table or on another object); on a convex surface the term is >= 0.
  // 0.3 is a fold of about 17 degrees between p and q. 0 disables.
  float concave_curvature = 0.3f;
  // ... and only where the fold is sharp: -(n_q - n_p) . (q - p) / |q - p|^2
  // above this, 1 / m. Where an object stands on another the faces meet in
  // an edge (a fold of 45-90 degrees within |q - p|, 40-100 / m at 1 m);
  // the inside of a bowl or cup bends smoothly, by 1 / its radius (12-40 / m
  // for a 2.5-8 cm radius), and stays one surface. 20 / m (5 cm) keeps
  // the learn scenes' hit ratio and detection cost and finds 42 of 46 bowls
  // in 40 synthetic piles instead of 39. 0 disables.
  float concave_min_curvature = 20.0f;
};

absl::Status Validate(const SurfaceEdgeOptions& options);

// Where the visible surface is not one smooth convex piece: occluding edges
// (depth jumps) and concave creases. Returns CV_8UC1 of the cloud's size,
// 255 on an edge, 0 elsewhere (also where there is no point). Both sides
// of a depth jump are marked, so components of "not an edge" never cross
// one. Used to split saliency components at object boundaries.
cv::Mat FindSurfaceEdges(const OrganizedCloud& cloud,
                         const SurfaceEdgeOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_SURFACE_EDGES_H_
