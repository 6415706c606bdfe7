#ifndef FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_H_
#define FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_H_

#include <Eigen/Core>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

// Surface models of incremental segmentation (thesis section 3.3, after
// Richtsfeld et al. 2012, "Segmentation of unknown objects in indoor
// environments"): a set of points is explained either by a plane or by a
// cubic B-spline height field, whichever has the shorter description
// length (MDL; Leonardis, Gupta & Bajcsy 1995, "Segmentation of range
// images as the search for geometric parametric models"), and two
// neighbouring surfaces are fused when one surface describes their union
// in fewer bits than the two apart.
//
// Description length of a model H of N points, bits:
//
//   DL(H) = kappa_parameter * log2(N) * P(H)              (model)
//         + sum_{explained i} (r_i / sigma_i)^2 / (2 ln 2)  (residuals)
//         + outlier_bits * #unexplained                     (the rest)
//
// P(H) the number of parameters and r_i point i's distance to the surface
// along the surface's normal n_i there (for a B-spline, the residual along
// w divided by |(-dw/dx, -dw/dy, 1)|, its first-order normal distance).
// sigma_i is the sensor's depth noise seen along n_i: depth z has noise
// sigma_z(z, theta) = sigma_per_z2 z^2 + grazing_sigma tan^2 theta (theta
// the angle between the viewing ray and n_i), which moves the point along
// its ray by sigma_z |p| / z, of which n_i sees the share cos theta:
// sigma_i^2 = (sigma_z |p_i . n_i| / z_i)^2 + surface_sigma^2 (the second
// term: what real surfaces and the sensor's calibration add). Measuring
// both models' residuals against the noise along their own normals keeps
// the comparison fair: a plane tilted away from the camera sees less of
// the depth noise than the B-spline's w axis would. Point i is explained
// when |r_i| <= tolerance_sigmas * sigma_i. The model term is Rissanen's
// two-part code (1983: a parameter estimated from N points is coded to
// precision 1 / sqrt(N), (1/2) log2 N bits); the residual term is the
// Gaussian code length of the residual less its constant part
// log2(sqrt(2 pi) sigma / delta), which every explained point pays alike;
// `outlier_bits` is what an unexplained point costs beyond that constant.
// This is Leonardis et al.'s savings S = N_explained - k1 P - k2 S_error
// with N - S turned into bits (lower is better).
//
// Held-out data bits. A model is fitted to some of the points and its
// residual and outlier bits are measured on others, each standing for
// N / (sample size) points: with fewer than min_bspline_points points all
// of them serve as both; up to 2 * max_fit_points, alternate points; else
// max_fit_points each, stratified over the input order (jittered cells,
// so a patch's raster order spreads them over its extent). Measuring on
// points the fit has not seen charges a B-spline for fitting noise (its
// surface then misses new points) instead of rewarding it, and lets a
// plane and a B-spline of a 100000-point table be compared on the same
// 400 points without the sample's chance advantage of one being scaled up
// 250 times against parameter bits that grow with log2(N) only. ShouldFuse
// samples each of its two inputs so, as FitSurface does alone, and
// measures the two models apart and the fused one on the same held-out
// points: a 100-point patch beside a 100000-point one is still seen.
//
// Cost, one 2.6 GHz core: one pass over the points (finite test and
// sampling; ~15 us for 20000), then linear in the samples: ~5 us for the
// plane and 15-30 us per B-spline grid tried (200 + 200 to 400 + 400
// points). FitSurface of a large curved patch tries 3-7 grids (~140 us in
// all); of a small planar one, none (~2 us at 100 points). Per 640 x 480
// OSD frame (tools/bench BM_SurfaceModel): ~1.4 ms for its ~30 default
// planar patches, ~2.3 ms for ~200 finer ones.

struct SurfaceModelOptions {
  // --- Noise model ---
  // Depth noise sigma_z = sigma_per_z2 * z^2 + ..., 1 / m (Khoshelham &
  // Elberink 2012: 1.43e-3 / m for the Kinect; also synth::NoiseOptions).
  // >= 0.
  float sigma_per_z2 = 1.43e-3f;
  // ... + grazing_sigma * tan^2 theta, metres: the growth of depth noise
  // on surfaces seen at a slant (Nguyen, Izadi & Lovell 2012, "Modeling
  // Kinect sensor noise": 0.1 mm * theta^2 / (pi/2 - theta)^2 / sqrt(z);
  // tan^2 theta is a close closed form, 3 against 4 at 60 degrees, and the
  // weak z factor is dropped). >= 0.
  float grazing_sigma = 1e-4f;
  // Deviation of real surfaces and of the sensor's calibration from the
  // ideal, metres, added to sigma_i in quadrature: cardboard faces bulge
  // and the Kinect has a spatially smooth depth distortion (Smisek et al.
  // 2011; Herrera et al. 2012 calibrate it away), each about a millimetre
  // at table-top range. Measured here: the default planar patches of OSD
  // learn0 and learn20 (boxes; faces at 0.6-0.7 m, where sigma_z is
  // 0.5-0.7 mm) leave an rms of 0.67 / 0.81 / 0.99 mm (quartiles) about
  // their best plane; 46 of their 60 patches come out as B-splines with
  // this term at 0.01 mm, 34 at 0.5 mm, 16 at 1 mm. Also keeps noise-free
  // input from demanding exact fits. > 0.
  float surface_sigma = 0.001f;
  // A point is explained by a model when its residual is at most this many
  // sigmas (the three-sigma rule; Richtsfeld 2012 and Leonardis 1995 use a
  // fixed noise band likewise). > 0.
  float tolerance_sigmas = 3.0f;

  // --- Description length ---
  // Bits per parameter per log2 of the number of points (Rissanen 1983's
  // (1/2) log2 N per parameter). > 0.
  float kappa_parameter = 0.5f;
  // Bits an unexplained point costs beyond an explained point at zero
  // residual: its offset coded uniformly over 1 m of depth (the table-top
  // working volume) at the explained code's resolution sqrt(2 pi) sigma,
  // sigma = 1.75 mm at 1 m (sigma_z and surface_sigma above): log2(1 m /
  // 4.4 mm) = 7.8, rounded to 8. Must be at least tolerance_sigmas^2 /
  // (2 ln 2) (6.5 bits at 3 sigma), the most an explained point costs, so
  // that explaining a point never costs more than leaving it unexplained.
  float outlier_bits = 8.0f;

  // --- B-spline ---
  // Largest control grid per parameter direction; the smallest is 4 (one
  // bicubic Bezier patch). The grid nu x nv is chosen by MDL too: from
  // 4 x 4, a row of control values is added along u or along v (the
  // shorter description of the two) while that shortens the description.
  // In [4, 12].
  int max_control = 6;
  // At most (fit points / points_per_control) control values, and never
  // fewer than 16 (a 6 x 6 grid from 360 fit points on). >= 1.
  float points_per_control = 10.0f;
  // Regularisation of the control values c (metres), relative to the mean
  // squared residual over the fit points (both m^2, so the weights are
  // dimensionless): smoothness_weight * sum of squared second differences
  // of c along u and along v (divided differences over the values'
  // Greville abscissae, scaled to 1 -2 1 on even ones; zero for a plane in
  // the frame): fills control values no point constrains by continuing
  // their neighbours. It penalises curvature too: 1e-6 bends a noise-free
  // paraboloid of 17 cm radius of curvature by 1.6 um, 1e-5 by 14 um ...
  // >= 0.
  float smoothness_weight = 1e-6f;
  // ... plus ridge_weight * sum c^2 (pulls towards the PCA plane w = 0;
  // keeps the normal equations positive definite). > 0.
  float ridge_weight = 1e-7f;
  // Fewer finite points than this: only the plane is fitted (a 4 x 4
  // spline has 16 control values; two points per value), on all of them.
  // >= 16.
  int min_bspline_points = 32;

  // --- Subsampling ---
  // Most points a model is fitted to, and most it is measured on (above).
  // Bounds the cost per patch; 400 points still put 11 on each of a 6 x 6
  // grid's control values. >= min_bspline_points.
  int max_fit_points = 400;

  // --- Fusion ---
  // ShouldFuse fuses when the saving DL(a) + DL(b) - DL(fused) exceeds
  // this, bits (0: the plain MDL comparison; its tests pass without a
  // bias). >= 0.
  float fusion_bias_bits = 0.0f;
};

// OK, or INVALID_ARGUMENT naming the field and the rule it broke.
absl::Status Validate(const SurfaceModelOptions& options);

enum class SurfaceKind { kPlane, kBSpline };

// A tensor-product cubic B-spline height field over a local frame. A point
// p (camera frame, metres) has local coordinates l = axes^T (p - origin);
// the columns of `axes` are the frame's x, y and w axes (right-handed; for
// a fit, the principal axes of its points by decreasing variance, w towards
// the camera). Its parameters are u = (l.x - min_uv.x) / (max_uv.x -
// min_uv.x) and v likewise from l.y, in [0, 1] over the sampled points'
// extent, and the surface is
//
//   w(u, v) = sum_{i < nu, j < nv} c_ij B_i(u) B_j(v),
//
// B_i the cubic B-splines of the clamped uniform knot vector on [0, 1]
// with nu - 3 spans (cubic_bspline.h; nu = 4: the Bernstein polynomials),
// c_ij = control(i * nv + j), metres.
struct BSplineSurface {
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector2f min_uv = Eigen::Vector2f::Zero();     // metres, local x / y
  Eigen::Vector2f max_uv = Eigen::Vector2f::Ones();     // metres, > min_uv
  int nu = 4;                                           // in [4, 12]
  int nv = 4;                                           // in [4, 12]
  Eigen::VectorXf control = Eigen::VectorXf::Zero(16);  // nu * nv, metres

  // w(u, v), metres; u and v are clamped to [0, 1]. Precondition
  // (checked): nu, nv in [4, 12] and control.size() == nu * nv.
  float Height(float u, float v) const;
  // The surface point at (u, v) (clamped to [0, 1]), camera frame.
  Eigen::Vector3f PointAt(float u, float v) const;
  // |l.w - w(u, v)| for p's local coordinates l, metres: the residual
  // along w. Outside the fitted extent u and v are clamped, so the surface
  // continues as its border's heights.
  float Distance(const Eigen::Vector3f& p) const;
};

struct SurfaceModel {
  SurfaceKind kind = SurfaceKind::kPlane;
  // n . p + d = 0, unit n towards the camera (n . centroid < 0), when
  // kPlane (the least-squares plane: through the centroid, normal the
  // smallest principal axis).
  Eigen::Vector4f plane = Eigen::Vector4f(0.0f, 0.0f, -1.0f, 0.0f);
  BSplineSurface spline;  // when kBSpline
  // DL(H) above, bits, for all finite input points (its data bits
  // estimated on the held-out sample).
  double description_length = 0.0;
  // Finite input points within tolerance (estimated on the held-out
  // sample, so it may differ from `points` by rounding when all are).
  int explained = 0;
  int points = 0;  // finite input points
  // Root mean square of r_i over the explained held-out points, metres.
  double rms = 0.0;
  int parameters = 0;  // P(H): 3 for a plane, nu * nv + 3 for a spline

  // Residual of p: |n . p + d| for a plane, spline.Distance(p) otherwise;
  // metres.
  float Distance(const Eigen::Vector3f& p) const;
};

// The least-squares plane of `points` (metres, camera frame; the fit
// sample's centroid and smallest principal axis) and its description
// length. Non-finite points (a NaN or infinite coordinate) are skipped
// everywhere below. Errors: invalid options; INVALID_ARGUMENT with fewer
// than 3 finite points. Collinear or coincident points give a plane
// through them (its normal some direction perpendicular to their line).
absl::StatusOr<SurfaceModel> FitPlaneModel(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options);

// The B-spline of `points` and its description length: the control values
// minimise the mean squared residual along w of the fit sample plus the
// regularisation of the options (linear least squares, normal equations
// summed per knot cell and solved by Cholesky), for the grid chosen as
// `max_control` describes. Errors: invalid options; INVALID_ARGUMENT with
// fewer than `min_bspline_points` finite points or when the points span no
// area (extent below 1 micrometre along the first or second principal
// axis).
absl::StatusOr<SurfaceModel> FitBSplineModel(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options);

// Fits both a plane and a B-spline to `points` and keeps the one with the
// smaller description length (the plane on a tie). The B-spline is not
// fitted when its 19 parameters alone would cost more than the plane's
// whole description (so most small planar patches cost a plane fit only).
// Fewer than `min_bspline_points` finite points, or points spanning no
// area: the plane. Errors: invalid options; INVALID_ARGUMENT with fewer
// than 3 finite points.
absl::StatusOr<SurfaceModel> FitSurface(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options);

struct FusionVerdict {
  bool fuse = false;
  // The surface of the union, chosen as FitSurface chooses: a B-spline, or
  // a plane when that is shorter (two coplanar patches). Fitted to both
  // inputs' samples, each point weighted by the input points it stands
  // for, so it may differ slightly from FitSurface of the concatenation.
  SurfaceModel fused;
  // DL(a) + DL(b) - DL(fused), bits; fuse == saving_bits > fusion_bias_bits.
  double saving_bits = 0.0;
};

// Whether the union of two neighbouring surfaces' points is better
// explained by one surface than by the two models apart (Richtsfeld et al.
// 2012's model merging): DL(fused) < DL(a) + DL(b) - fusion_bias_bits.
// `model_a` and `model_b` are the models of `a` and `b` (normally
// FitSurface(a) and FitSurface(b) with the same options); DL(a) and DL(b)
// are their parameter bits plus their data bits re-measured on the same
// held-out points as the fused model's (equal to their
// description_length when they are FitSurface's). Neither input need
// have a point; the union needs 3. Errors: invalid options;
// INVALID_ARGUMENT when the union has fewer than 3 finite points.
absl::StatusOr<FusionVerdict> ShouldFuse(const std::vector<Eigen::Vector3f>& a,
                                         const SurfaceModel& model_a,
                                         const std::vector<Eigen::Vector3f>& b,
                                         const SurfaceModel& model_b,
                                         const SurfaceModelOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_SURFACE_MODEL_H_
