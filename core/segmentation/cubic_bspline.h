#ifndef FOVEA_CORE_SEGMENTATION_CUBIC_BSPLINE_H_
#define FOVEA_CORE_SEGMENTATION_CUBIC_BSPLINE_H_

namespace fovea {

// Cubic B-spline basis functions of a clamped uniform knot vector on
// [0, 1]: n functions (n - 3 equal spans; knots 0, 0, 0, 0, 1/(n-3), ...,
// 1, 1, 1, 1), the basis of surface_model.h's BSplineSurface. n = 4 gives
// the Bernstein polynomials of one cubic Bezier segment.

inline constexpr int kCubicOrder = 4;  // non-zero functions on each span
inline constexpr int kMinCubicBasis = 4;
inline constexpr int kMaxCubicBasis = 12;

// The 4 functions non-zero at t (clamped to [0, 1]) for n in
// [kMinCubicBasis, kMaxCubicBasis], into b[0..3], and unless null their
// derivatives d/dt into db[0..3]; returns the index of the first (b[k] is
// B_{first + k}), in [0, n - 4]. On [0, 1] the functions are non-negative
// and sum to 1. Evaluated from per-span cubic polynomials tabulated once
// (on first use, thread-safe) from the Cox-de Boor recursion.
int CubicBSplineBasis(float t, int n, float* b, float* db = nullptr);

// The same by the Cox-de Boor recursion in triangular form (Piegl &
// Tiller, The NURBS Book, 2nd ed., algorithm A2.2), in double, without
// derivatives: slow (divisions); the reference the tables come from.
int CubicBSplineBasisReference(double t, int n, double* b);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_CUBIC_BSPLINE_H_
