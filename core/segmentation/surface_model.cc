// The surface models' choice between a plane and a B-spline, their fusion
// test and the public API; the samples, code lengths and B-spline fit are
// in the files surface_model_internal.h names.

#include "core/segmentation/surface_model.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/segmentation/bspline_fit.h"
#include "core/segmentation/cubic_bspline.h"
#include "core/segmentation/description_length.h"
#include "core/segmentation/surface_model_internal.h"
#include "core/segmentation/surface_sampling.h"

namespace fovea {
namespace surface_model_internal {

float HeightAndGradient(const BSplineSurface& spline, float u, float v,
                        Eigen::Vector2f* gradient) {
  FOVEA_CHECK(spline.nu >= kMinCubicBasis && spline.nv >= kMinCubicBasis &&
              spline.nu <= kMaxCubicBasis && spline.nv <= kMaxCubicBasis &&
              spline.control.size() == spline.nu * spline.nv);
  Eigen::Vector4f bu, bv, dbu, dbv;
  const bool slope = gradient != nullptr;
  const int su =
      CubicBSplineBasis(u, spline.nu, bu.data(), slope ? dbu.data() : nullptr);
  const int sv =
      CubicBSplineBasis(v, spline.nv, bv.data(), slope ? dbv.data() : nullptr);
  Eigen::Vector4f along_u = Eigen::Vector4f::Zero();
  Eigen::Vector4f along_u_slope = Eigen::Vector4f::Zero();
  for (int i = 0; i < kOrder; ++i) {
    const Eigen::Map<const Eigen::Vector4f> row(spline.control.data() +
                                                (su + i) * spline.nv + sv);
    along_u += bu(i) * row;
    if (slope) along_u_slope += dbu(i) * row;
  }
  if (slope) {
    *gradient = Eigen::Vector2f(along_u_slope.dot(bv), along_u.dot(dbv));
  }
  return along_u.dot(bv);
}

}  // namespace surface_model_internal

using surface_model_internal::AddResidual;
using surface_model_internal::BSplineOf;
using surface_model_internal::BuildSamples;
using surface_model_internal::DataCode;
using surface_model_internal::HeightAndGradient;
using surface_model_internal::kBitsPerSquaredSigma;
using surface_model_internal::kPlaneParameters;
using surface_model_internal::ParameterBits;
using surface_model_internal::Samples;

namespace {

SurfaceModel PlaneOf(const Samples& s, const SurfaceModelOptions& options) {
  SurfaceModel model;
  model.kind = SurfaceKind::kPlane;
  const Eigen::Vector3f n = s.axes.col(2);
  model.plane = Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(s.origin));
  DataCode code(options);
  for (size_t i = 0; i < s.eval.size(); ++i) {
    AddResidual(model, s.eval[i], s.eval_weight[i], code);
  }
  code.Finish(s.finite, kPlaneParameters, model);
  return model;
}

// The plane or the B-spline of `s`, whichever has the shorter description
// (the plane on a tie, and when no B-spline can be fitted: too few points,
// no area).
absl::StatusOr<SurfaceModel> ChooseModel(const Samples& s,
                                         const SurfaceModelOptions& options) {
  SurfaceModel plane = PlaneOf(s, options);
  // No B-spline is shorter than its parameter bits: skip the fit when even
  // the 4 x 4 grid's cost more than the plane's whole description.
  if (plane.description_length <=
      ParameterBits(s.finite,
                    kMinCubicBasis * kMinCubicBasis + kPlaneParameters,
                    options)) {
    return plane;
  }
  absl::StatusOr<SurfaceModel> spline =
      BSplineOf(s, options, plane.description_length);
  if (spline.ok() && spline->description_length < plane.description_length) {
    return *std::move(spline);
  }
  if (!spline.ok() && !absl::IsInvalidArgument(spline.status())) {
    return spline.status();
  }
  return plane;
}

}  // namespace

absl::Status Validate(const SurfaceModelOptions& options) {
  auto invalid = [](const char* field, const std::string& rule, double value) {
    return absl::InvalidArgumentError(absl::StrCat(
        "surface_model.", field, " must be ", rule, ", got ", value));
  };
  auto finite = [](double value) { return std::isfinite(value); };
  if (!(options.sigma_per_z2 >= 0.0f) || !finite(options.sigma_per_z2)) {
    return invalid("sigma_per_z2", ">= 0", options.sigma_per_z2);
  }
  if (!(options.grazing_sigma >= 0.0f) || !finite(options.grazing_sigma)) {
    return invalid("grazing_sigma", ">= 0", options.grazing_sigma);
  }
  if (!(options.surface_sigma > 0.0f) || !finite(options.surface_sigma)) {
    return invalid("surface_sigma", "> 0", options.surface_sigma);
  }
  if (!(options.tolerance_sigmas > 0.0f) || !finite(options.tolerance_sigmas)) {
    return invalid("tolerance_sigmas", "> 0", options.tolerance_sigmas);
  }
  if (!(options.kappa_parameter > 0.0f) || !finite(options.kappa_parameter)) {
    return invalid("kappa_parameter", "> 0", options.kappa_parameter);
  }
  const double most_explained_bits =
      static_cast<double>(options.tolerance_sigmas) * options.tolerance_sigmas *
      kBitsPerSquaredSigma;
  if (!(options.outlier_bits >= most_explained_bits) ||
      !finite(options.outlier_bits)) {
    return invalid("outlier_bits",
                   absl::StrCat(">= tolerance_sigmas^2 / (2 ln 2) = ",
                                most_explained_bits),
                   options.outlier_bits);
  }
  if (options.max_control < kMinCubicBasis ||
      options.max_control > kMaxCubicBasis) {
    return invalid(
        "max_control",
        absl::StrCat("in [", kMinCubicBasis, ", ", kMaxCubicBasis, "]"),
        options.max_control);
  }
  if (!(options.points_per_control >= 1.0f) ||
      !finite(options.points_per_control)) {
    return invalid("points_per_control", ">= 1", options.points_per_control);
  }
  if (!(options.smoothness_weight >= 0.0f) ||
      !finite(options.smoothness_weight)) {
    return invalid("smoothness_weight", ">= 0", options.smoothness_weight);
  }
  if (!(options.ridge_weight > 0.0f) || !finite(options.ridge_weight)) {
    return invalid("ridge_weight", "> 0", options.ridge_weight);
  }
  if (options.min_bspline_points < kMinCubicBasis * kMinCubicBasis) {
    return invalid("min_bspline_points", ">= 16", options.min_bspline_points);
  }
  if (options.max_fit_points < options.min_bspline_points) {
    return invalid("max_fit_points", ">= min_bspline_points",
                   options.max_fit_points);
  }
  if (!(options.fusion_bias_bits >= 0.0f) ||
      !finite(options.fusion_bias_bits)) {
    return invalid("fusion_bias_bits", ">= 0", options.fusion_bias_bits);
  }
  return absl::OkStatus();
}

float BSplineSurface::Height(float u, float v) const {
  return HeightAndGradient(*this, u, v, nullptr);
}

Eigen::Vector3f BSplineSurface::PointAt(float u, float v) const {
  u = std::clamp(u, 0.0f, 1.0f);
  v = std::clamp(v, 0.0f, 1.0f);
  const Eigen::Vector2f xy =
      min_uv + Eigen::Vector2f(u, v).cwiseProduct(max_uv - min_uv);
  return origin + axes * Eigen::Vector3f(xy.x(), xy.y(), Height(u, v));
}

float BSplineSurface::Distance(const Eigen::Vector3f& p) const {
  const Eigen::Vector3f l = axes.transpose() * (p - origin);
  const Eigen::Vector2f uv =
      (l.head<2>() - min_uv).cwiseQuotient(max_uv - min_uv);
  return std::abs(l.z() - Height(uv.x(), uv.y()));
}

float SurfaceModel::Distance(const Eigen::Vector3f& p) const {
  if (kind == SurfaceKind::kBSpline) return spline.Distance(p);
  return std::abs(plane.head<3>().dot(p) + plane.w());
}

absl::StatusOr<SurfaceModel> FitPlaneModel(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_ASSIGN_OR_RETURN(Samples s, BuildSamples({&points}, options));
  return PlaneOf(s, options);
}

absl::StatusOr<SurfaceModel> FitBSplineModel(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_ASSIGN_OR_RETURN(Samples s, BuildSamples({&points}, options));
  return BSplineOf(s, options);
}

absl::StatusOr<SurfaceModel> FitSurface(
    const std::vector<Eigen::Vector3f>& points,
    const SurfaceModelOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_ASSIGN_OR_RETURN(Samples s, BuildSamples({&points}, options));
  return ChooseModel(s, options);
}

absl::StatusOr<FusionVerdict> ShouldFuse(const std::vector<Eigen::Vector3f>& a,
                                         const SurfaceModel& model_a,
                                         const std::vector<Eigen::Vector3f>& b,
                                         const SurfaceModel& model_b,
                                         const SurfaceModelOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_ASSIGN_OR_RETURN(Samples s, BuildSamples({&a, &b}, options));
  FOVEA_ASSIGN_OR_RETURN(SurfaceModel fused, ChooseModel(s, options));
  // The two models apart, measured on the same held-out points.
  DataCode apart(options);
  for (size_t i = 0; i < s.eval.size(); ++i) {
    AddResidual(s.eval_stratum[i] == 0 ? model_a : model_b, s.eval[i],
                s.eval_weight[i], apart);
  }
  const double apart_bits =
      ParameterBits(s.stratum_finite[0], model_a.parameters, options) +
      ParameterBits(s.stratum_finite[1], model_b.parameters, options) +
      apart.bits();
  FusionVerdict verdict;
  verdict.saving_bits = apart_bits - fused.description_length;
  verdict.fuse = verdict.saving_bits > options.fusion_bias_bits;
  verdict.fused = std::move(fused);
  return verdict;
}

}  // namespace fovea
