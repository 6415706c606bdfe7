#ifndef FOVEA_CORE_SEGMENTATION_DESCRIPTION_LENGTH_H_
#define FOVEA_CORE_SEGMENTATION_DESCRIPTION_LENGTH_H_

// The MDL code lengths of the surface models (surface_model.h, "Description
// length"): Rissanen's parameter bits, and the data bits of held-out points
// under the sensor's noise along the surface normal. Internal to
// core/segmentation (surface_model_internal.h).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "core/segmentation/surface_model.h"

namespace fovea::surface_model_internal {

// Depths and cosines are floored at these in the noise model (a point at
// the camera, a surface seen edge-on).
inline constexpr float kMinDepth = 1e-3f;  // metres
inline constexpr float kMinCos = 1e-2f;
inline constexpr double kLn2 = 0.69314718055994530942;
// Bits of a Gaussian residual per squared sigma: 1 / (2 ln 2).
inline constexpr double kBitsPerSquaredSigma = 1.0 / (2.0 * kLn2);

// Rissanen's parameter bits for `parameters` parameters of N points.
double ParameterBits(int points, int parameters,
                     const SurfaceModelOptions& options);

// The data bits of DL(H) and the statistics of explained points, summed
// over weighted held-out points.
class DataCode {
 public:
  explicit DataCode(const SurfaceModelOptions& options)
      : options_(options),
        tolerance2_(options.tolerance_sigmas * options.tolerance_sigmas) {}

  // A point p (camera frame) standing for `weight` input points at
  // `distance` (metres, signed) from a surface whose unit normal there is
  // `normal`.
  void Add(const Eigen::Vector3f& p, float distance,
           const Eigen::Vector3f& normal, float weight) {
    const float p_dot_n = p.dot(normal);
    AddSquared(p.z(), p.squaredNorm(), p_dot_n * p_dot_n, distance * distance,
               weight);
  }

  // The same from squares (no roots on the hot path): the point's depth z,
  // |p|^2, (p . n)^2 and the squared distance.
  void AddSquared(float z, float range2, float p_dot_n2, float distance2,
                  float weight) {
    const float e2 = distance2 / NormalVariance(z, range2, p_dot_n2);
    if (e2 <= tolerance2_) {
      bits_ += weight * (e2 * kBitsPerSquaredSigma);
      explained_ += weight;
      sum_r2_ += weight * distance2;
    } else {
      bits_ += weight * options_.outlier_bits;
    }
  }

  double bits() const { return bits_; }

  // Fills the model's statistics and description length for `points`
  // finite input points and `parameters` parameters.
  void Finish(int points, int parameters, SurfaceModel& model) const {
    model.points = points;
    model.parameters = parameters;
    model.explained = static_cast<int>(std::lround(explained_));
    model.rms = explained_ > 0.0 ? std::sqrt(sum_r2_ / explained_) : 0.0;
    model.description_length =
        ParameterBits(points, parameters, options_) + bits_;
  }

 private:
  // sigma_i^2 of the header: the depth noise sigma_z(z, theta) moved
  // along the ray (|p| / z) and projected on the normal (cos theta), so
  // times |p . n| / z, plus surface_sigma^2. With z2 = z^2, c2 = (p . n)^2
  // and tan^2 theta = (|p|^2 - c2) / c2 that is
  // (sigma_per_z2 z2 c2 + grazing_sigma (|p|^2 - c2))^2 / (c2 z2) + ...
  float NormalVariance(float z, float range2, float p_dot_n2) const {
    const float z2 = std::max(z * z, kMinDepth * kMinDepth);
    range2 = std::max(range2, kMinDepth * kMinDepth);
    p_dot_n2 = std::max(p_dot_n2, kMinCos * kMinCos * range2);
    const float numerator =
        options_.sigma_per_z2 * z2 * p_dot_n2 +
        options_.grazing_sigma * std::max(0.0f, range2 - p_dot_n2);
    return numerator * numerator / (p_dot_n2 * z2) +
           options_.surface_sigma * options_.surface_sigma;
  }

  const SurfaceModelOptions& options_;
  const float tolerance2_;
  double explained_ = 0.0;
  double bits_ = 0.0;
  double sum_r2_ = 0.0;
};

// Adds camera-frame point p's residual under `model` to `code`. A
// spline's normal is (-dw/dx, -dw/dy, 1) in its local frame (x, y
// metres), normalised; the distance along it is the residual along w over
// that vector's length (to first order).
void AddResidual(const SurfaceModel& model, const Eigen::Vector3f& p,
                 float weight, DataCode& code);

}  // namespace fovea::surface_model_internal

#endif  // FOVEA_CORE_SEGMENTATION_DESCRIPTION_LENGTH_H_
