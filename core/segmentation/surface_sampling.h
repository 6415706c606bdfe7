#ifndef FOVEA_CORE_SEGMENTATION_SURFACE_SAMPLING_H_
#define FOVEA_CORE_SEGMENTATION_SURFACE_SAMPLING_H_

// The samples a surface model is fitted to and the held-out samples its
// description is measured on (surface_model.h, "Held-out data bits"), with
// the principal frame of the fit sample. Internal to core/segmentation
// (surface_model_internal.h).

#include <Eigen/Core>
#include <initializer_list>
#include <vector>

#include "absl/status/statusor.h"
#include "core/segmentation/surface_model.h"

namespace fovea::surface_model_internal {

// The points a model is fitted to and the held-out points its description
// is measured on, each with the number of input points it stands for
// (its weight), drawn per stratum (one input, or the two of a fusion).
struct Samples {
  int finite = 0;                   // N: finite input points, all strata
  std::vector<int> stratum_finite;  // per stratum
  std::vector<Eigen::Vector3f> fit, eval;
  std::vector<float> fit_weight, eval_weight;
  std::vector<int> eval_stratum;
  // Principal axes of the weighted fit points (x, y, w columns).
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
};

// The samples of the finite points of `strata` (one input, or the two of
// a fusion; stratum k is the k-th), drawn per stratum as surface_model.h
// describes, and the principal axes of the weighted fit points (x, y, w by
// decreasing variance, w towards the camera; the identity when the eigen
// decomposition fails). INVALID_ARGUMENT with fewer than 3 finite points
// in all.
absl::StatusOr<Samples> BuildSamples(
    std::initializer_list<const std::vector<Eigen::Vector3f>*> strata,
    const SurfaceModelOptions& options);

}  // namespace fovea::surface_model_internal

#endif  // FOVEA_CORE_SEGMENTATION_SURFACE_SAMPLING_H_
