#ifndef FOVEA_CORE_SEGMENTATION_POLAR_CONTOUR_H_
#define FOVEA_CORE_SEGMENTATION_POLAR_CONTOUR_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"

namespace fovea {

// How a sample of edge probability p becomes the cost of the contour
// passing through it.
enum class PolarCost {
  kOneMinusP,  // 1 - p
  kNegLogP,    // -log(max(p, PolarContourOptions::min_probability))
};

struct PolarContourOptions {
  // Angles the circle is divided into; one radius per angle.
  int angles = 360;
  // Distance between radial samples, pixels.
  float radial_step_px = 1.0f;
  // The contour stays between these radii, pixels of the map (not scaled
  // with the focal length; 250 px is the radius of a 48 cm object 0.5 m
  // from a Kinect, f = 525 px).
  float min_radius_px = 4.0f;
  float max_radius_px = 250.0f;
  // Edge probability read past the image border: the prior p(E) = 0.5 of
  // eq. 3.5, nothing known. A contour then closes along the border where
  // an object is cut by it (cheaper than through the object's inside), but
  // the border is no free way around the fixation as p = 1 would make it.
  float outside_probability = 0.5f;
  // Steepest contour allowed: from one angle to the next the radius may
  // change by max(1 step, max_slope * r * dtheta), i.e. the contour may be
  // up to atan(max_slope) from the circle through it (5: 79 degrees, which
  // lets it follow the sides of a box seen from inside).
  float max_slope = 5.0f;
  // Each step's cost is the cost of the sample it ends on times the
  // step's length in log-polar coordinates, sqrt(dtheta^2 + (dr / r)^2) /
  // dtheta: a circle of any radius costs the same per angle (no pull
  // towards the fixation, Mishra et al. 2009), a radial run costs its
  // relative length. False: the sample's cost alone.
  bool log_polar_length = true;
  // How a sample's p becomes its cost; -log p lets a few strong samples
  // outweigh many middling ones (on the OSD learn scenes both give the
  // same F to 0.01).
  PolarCost cost = PolarCost::kNegLogP;
  // Floor of p under kNegLogP, (0, 1).
  float min_probability = 0.01f;
  // The interrupt is asked every this many angles of each pass, >= 1.
  int interrupt_every_angles = 32;
};

// OK, or INVALID_ARGUMENT naming the field: angles in [8, 4096], radial
// step in [0.25, 16], 0 < min_radius < max_radius <= 4096, max_slope in
// (0, 1000],
// outside_probability in [0, 1], min_probability in (0, 1),
// interrupt_every_angles >= 1.
absl::Status Validate(const PolarContourOptions& options);

// The closed contour of SegmentAtFixation in polar form: radius (pixels)
// at angle 2 pi i / radii.size() around the seed, angle 0 along +u,
// increasing towards +v.
struct PolarContour {
  cv::Point seed;
  std::vector<float> radii;
  double cost = 0.0;  // summed step costs of the contour
};

// The minimum-cost closed contour around `seed` in `edge_probability`
// (CV_32FC1, [0, 1], NaN read as 1, past the border
// options.outside_probability), after Mishra et al. 2009 "Active
// segmentation with fixation": the map is resampled (bilinear) on a polar
// grid around the seed, and dynamic programming over the angles finds the
// one radius per angle, each step within the slope limit, that minimises
// the summed cost (low where the edge probability is high). Closure
// r(0) = r(2 pi): a first pass leaves the start free; the second starts
// and ends at the radius the first found opposite its start, so the
// contour returned is closed and optimal among those through that point.
// Errors: invalid options, an empty or non-CV_32FC1 map, seed outside it
// (INVALID_ARGUMENT); whatever `interrupt` returns (asked before the
// resampling and every options.interrupt_every_angles angles of each pass);
// RESOURCE_EXHAUSTED when memory runs out. Work: angles x radii x (slope
// window) per pass, about 4 ms at the defaults.
absl::StatusOr<PolarContour> FindPolarContour(
    const cv::Mat& edge_probability, cv::Point seed,
    const PolarContourOptions& options, const InterruptCheck& interrupt = {});

// The inside of a polar contour filled: CV_8UC1 of `size`, 255 inside
// (and on) the polygon through the contour's points, 0 elsewhere.
cv::Mat FillPolarContour(const PolarContour& contour, cv::Size size);

// FindPolarContour then FillPolarContour: the object mask at the fixation,
// CV_8UC1 of the map's size, 255 inside. Errors as FindPolarContour's.
absl::StatusOr<cv::Mat> SegmentAtFixation(const cv::Mat& edge_probability,
                                          cv::Point seed,
                                          const PolarContourOptions& options,
                                          const InterruptCheck& interrupt = {});

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_POLAR_CONTOUR_H_
