#ifndef FOVEA_CORE_SEGMENTATION_EDGE_MAPS_H_
#define FOVEA_CORE_SEGMENTATION_EDGE_MAPS_H_

#include <opencv2/core.hpp>

#include "absl/status/status.h"
#include "core/frame/organized_cloud.h"

namespace fovea {

// Options of the three edge maps of edge-based segmentation (thesis
// section 3.2.3). Pixel sizes are given at a 525 px focal length (a Kinect
// v1 at 640 x 480) and scaled by fx / 525, at least 1 px, so the maps of a
// pyramid level see the same neighbourhood in the scene.
struct EdgeMapOptions {
  // Sigma of the Gaussian the colour image is smoothed with before the
  // Sobel operator, pixels at f = 525; 0 disables. 1 px takes out most of
  // a Kinect's Bayer and compression noise without moving edges.
  float color_blur_sigma_px = 1.0f;
  // Aperture of the Sobel operator on colour: 3, 5 or 7.
  int sobel_aperture = 3;
  // Depth differences are taken between pixels this far either side of
  // the centre (a Sobel pattern with taps at +-r), pixels at f = 525. 2 px
  // reaches across the one- or two-pixel ramp a Kinect draws at an
  // occluding edge and averages its disparity quantisation.
  int depth_radius_px = 2;
  // Curvature edges compare the normals of the pixel pairs this far either
  // side of a pixel, pixels at f = 525. The normals are smoothed over about
  // 5 px (NormalOptions::baseline_m at 1 m), so pairs must reach past that
  // to see both faces of a fold (FindSurfaceEdges uses 6 px likewise).
  int curvature_radius_px = 6;
  // Give curvature edges the sign of the fold: + where the normals of the
  // pair converge (concave, where an object stands on the table or touches
  // another), - where they diverge (convex, the rim of a box, a cylinder's
  // side). Object boundaries are concave or occluding; convex folds lie
  // inside objects, so the sign tells the trained model which is which.
  // False keeps the thesis's unsigned measure.
  bool signed_curvature = true;
};

// OK, or INVALID_ARGUMENT naming the field: blur sigma in [0, 10], Sobel
// aperture 3, 5 or 7, radii in [1, 16].
absl::Status Validate(const EdgeMapOptions& options);

// Three edge maps of one frame, each CV_32FC1 of the cloud's size, NaN
// where undefined.
struct EdgeMaps {
  // SC: colour gradient, the largest over the three channels of the
  // smoothed 8-bit CIE Lab image (OpenCV's scaling: L * 255 / 100,
  // a + 128, b + 128) of the Sobel gradient magnitude, scaled so that a
  // step between two flat colours reads the step's height; >= 0. Defined
  // everywhere (colour needs no depth).
  cv::Mat color;
  // SD: depth gradient over the depth itself, the magnitude of a Sobel
  // pattern with taps at +-depth_radius_px, scaled so that a step from z to
  // z (1 + f) reads about f at any range; >= 0. NaN where the pixel has no
  // depth; a tap without depth takes the centre's depth, so the far side of
  // a jump edged by a shadow reads less than the whole jump.
  cv::Mat depth;
  // CE: curvature edge, the largest 1 - n_a . n_b over the four pairs of
  // pixels (a, b) at -+curvature_radius_px through the pixel (horizontal,
  // vertical, both diagonals) that have normals; in [0, 2], 0 on a plane,
  // largest where the pixel sits on a fold between a and b. With
  // signed_curvature, negated where that pair's fold is convex
  // ((n_b - n_a) . (x_b - x_a) > 0); then in [-2, 2]. NaN where the pixel
  // or every pair lacks a normal.
  cv::Mat curvature;
};

// The edge maps SC, SD and CE of thesis section 3.2.3 from an organized
// cloud with normals (BuildOrganizedCloud); `cloud.color` must be CV_8UC3
// RGB of the cloud's size. Precondition (checked): Validate(options) is OK
// and the cloud's matrices have the types of OrganizedCloud. An empty
// cloud gives empty maps. Linear in the pixels.
EdgeMaps ComputeEdgeMaps(const OrganizedCloud& cloud,
                         const EdgeMapOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_EDGE_MAPS_H_
