#ifndef FOVEA_CORE_SEGMENTATION_BSPLINE_FIT_H_
#define FOVEA_CORE_SEGMENTATION_BSPLINE_FIT_H_

// The B-spline surface model (surface_model.h's FitBSplineModel): the
// control values by penalised weighted least squares (smoothness and ridge
// terms, normal equations summed per knot cell, Cholesky), the control
// grid grown by MDL. Internal to core/segmentation
// (surface_model_internal.h).

#include <limits>

#include "absl/status/statusor.h"
#include "core/segmentation/surface_model.h"
#include "core/segmentation/surface_sampling.h"

namespace fovea::surface_model_internal {

// The B-spline of `s`, its grid chosen by MDL. Grids whose parameter bits
// alone reach `ceiling` are not tried beyond 4 x 4 (they could not be
// chosen over a model of that description length).
// Errors: INVALID_ARGUMENT with fewer than min_bspline_points finite
// points or when the samples span no area; INTERNAL when the normal
// equations cannot be solved.
absl::StatusOr<SurfaceModel> BSplineOf(
    const Samples& s, const SurfaceModelOptions& options,
    double ceiling = std::numeric_limits<double>::infinity());

}  // namespace fovea::surface_model_internal

#endif  // FOVEA_CORE_SEGMENTATION_BSPLINE_FIT_H_
