#ifndef FOVEA_CORE_SEGMENTATION_BODY_FIT_H_
#define FOVEA_CORE_SEGMENTATION_BODY_FIT_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "absl/status/status.h"

namespace fovea {

// One curved body: whether the points of two surfaces lie together on one
// sphere or on one upright cylinder (its axis along the support's normal).
// A bowl's inside and outside meet at its rim, a mug's inside and its side
// at the mug's, where the camera sees a depth jump and no fold; a can's
// side cut into strips has folds too slight to call convex. A sphere or a
// cylinder through both surfaces joins them where the relation SVM doubts
// (IncOptions::body_join); a cup in a bowl, a can beside a can, a ball on a
// box lie on no one body.

struct BodyFitOptions {
  // Each surface needs this many points: a few dozen fit any sphere.
  int min_points = 150;
  // The body's radius, metres: household bowls, cups and cans; a larger
  // sphere is a plane's fit.
  float min_radius_m = 0.02f;
  float max_radius_m = 0.2f;
  // The points' root mean square distance to the body may be at most
  // hypot(wall_m, sigma(z)), metres: half a bowl's or a mug's wall (its
  // inside and outside are radii a wall apart) and the sensor's depth noise
  // sigma(z) = sigma0_m + sigma_per_z2 z^2 at the points' mean depth z
  // (the Kinect's by default; AdaptToSensor sets the sensor's).
  float wall_m = 0.002f;
  float sigma0_m = 0.0f;
  float sigma_per_z2 = 1.43e-3f;
  // Each surface is sampled down to at most this many points for the fit.
  int max_fit_points = 400;
  // An upright cone is a body too (a tapered mug, a tub, a flower pot) when
  // its radius changes by at most this much per metre of height (0.3: 17
  // degrees off vertical); 0: cylinders only.
  float max_taper = 0.3f;
  // A vessel's inside and outside are one body too, their radii at most
  // this far apart (a mug's or a bowl's wall): the second surface's radius
  // is fitted on its own, its axis or centre and its taper shared, and each
  // surface must be curved beyond the noise. The cones need max_taper > 0.
  // 0 (the default): no walls. 0.008 raised OSD rolled cylindric objects
  // above 0.75 F from 0.799 to 0.826 and lowered nothing on the scorecard,
  // but joined a bowl and the box beside it in one synthetic drift sequence
  // (2 more identity switches in 30; docs/scorecard.md).
  float max_wall_m = 0.0f;
};

absl::Status Validate(const BodyFitOptions& options);

struct BodyFit {
  Eigen::Vector3f center = Eigen::Vector3f::Zero();  // a point on the axis
  float radius = 0.0f;  // metres; a cone's at the height of `center`
  float rms = 0.0f;     // metres
  float taper = 0.0f;   // a cone's radius change per metre along `up`
  float wall = 0.0f;    // a walled fit's second radius minus its first
};

// The rms distance of the points in [first, last) to their least-squares
// plane: the square root of their covariance's smallest eigenvalue; 0 for
// fewer than 3 points.
double PlaneRms(std::vector<Eigen::Vector3f>::const_iterator first,
                std::vector<Eigen::Vector3f>::const_iterator last);

// The least-squares sphere through `points` (algebraic fit: |p|^2 + D.p + F
// = 0 solved linearly, then the geometric rms); nullopt for fewer than 4
// points or a degenerate fit.
std::optional<BodyFit> FitSphere(const std::vector<Eigen::Vector3f>& points);

// The least-squares cylinder of axis `up` (unit) through `points`: a circle
// fitted to their projection on the plane normal to `up`; `center` is on
// the axis. nullopt for fewer than 3 points or a degenerate fit.
std::optional<BodyFit> FitUprightCylinder(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& up);

// The least-squares cone of axis `up` through `points`: the radius r0 +
// taper h at height h along `up` above `center` (the points' mean height),
// by Gauss-Newton on the points' distances from the cylinder's fit.
// nullopt for fewer than 5 points or a degenerate fit.
std::optional<BodyFit> FitUprightCone(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& up);

// Whether `a` and `b` (camera frame: z is depth) lie together on one
// sphere, one cylinder or one cone (options.max_taper) of axis `up` within
// `options`.
bool OnOneBody(const std::vector<Eigen::Vector3f>& a,
               const std::vector<Eigen::Vector3f>& b, const Eigen::Vector3f& up,
               const BodyFitOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_BODY_FIT_H_
