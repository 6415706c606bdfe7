#ifndef FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_INTERNAL_H_
#define FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_INTERNAL_H_

// What the pieces of the surface models (surface_model.h) share: the
// spline order, a plane's parameter count and the spline's evaluation with
// its gradient. The pieces: surface_sampling.h (the fit and held-out
// samples), description_length.h (the MDL code lengths), bspline_fit.h (the
// penalised least-squares B-spline and its grid) and surface_model.cc
// (the plane, the model choice and the public API). Internal to
// core/segmentation; tests reach the behaviour through surface_model.h.

#include <Eigen/Core>

#include "core/segmentation/cubic_bspline.h"
#include "core/segmentation/surface_model.h"

namespace fovea::surface_model_internal {

inline constexpr int kOrder = kCubicOrder;
// Parameters of a plane (3 degrees of freedom); a spline has its control
// values plus the same three for its frame's w = 0 plane.
inline constexpr int kPlaneParameters = 3;

// w(u, v) of `spline` and, unless null, its gradient (dw/du, dw/dv).
float HeightAndGradient(const BSplineSurface& spline, float u, float v,
                        Eigen::Vector2f* gradient);

}  // namespace fovea::surface_model_internal

#endif  // FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_INTERNAL_H_
