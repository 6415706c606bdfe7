#include "core/segmentation/bspline_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/segmentation/cubic_bspline.h"
#include "core/segmentation/description_length.h"
#include "core/segmentation/surface_model_internal.h"

namespace fovea::surface_model_internal {
namespace {

constexpr int kOrder2 = kOrder * kOrder;
// Points spanning less than this along the first or second principal axis
// span no area (no (u, v) parameterisation), metres.
constexpr float kMinExtent = 1e-6f;

using Matrix16f = Eigen::Matrix<float, kOrder2, kOrder2>;
using Vector16f = Eigen::Matrix<float, kOrder2, 1>;

// A sample in a spline's parameters: u and v normalised over the extent,
// height w and weight; for held-out points also what sigma needs: camera
// depth z, |p|^2 and q = axes^T p (so that p . (axes t) = q . t).
struct SplineData {
  std::vector<float> u, v, w, weight, z, range2;
  std::vector<Eigen::Vector3f> q;
};

// The 4 non-zero basis functions of one direction (grid size n) at each
// sample parameter, their derivatives per metre and the first's index.
struct DirectionBasis {
  std::vector<int> first;
  std::vector<Eigen::Vector4f> value, slope;
};

DirectionBasis TabulateBasis(const std::vector<float>& t, int n, float extent) {
  DirectionBasis basis;
  basis.first.resize(t.size());
  basis.value.resize(t.size());
  basis.slope.resize(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    basis.first[i] = CubicBSplineBasis(t[i], n, basis.value[i].data(),
                                       basis.slope[i].data());
    basis.slope[i] /= extent;
  }
  return basis;
}

// The second divided differences of n control values over their Greville
// abscissae xi_i = (knot_{i+1} + knot_{i+2} + knot_{i+3}) / 3 (the
// parameters where they act; for clamped knots unevenly spaced near the
// ends), times the squared mean spacing 1 / (n - 1)^2: row i - 1 holds the
// coefficients of c_{i-1}, c_i, c_{i+1}, 1 -2 1 where the abscissae are
// even. Zero for control values of an affine function, which sit at
// a + b xi_i.
std::vector<std::array<double, 3>> SecondDifferences(int n) {
  const int spans = n - 3;
  auto knot = [spans](int i) {
    return std::clamp(i - 3, 0, spans) / static_cast<double>(spans);
  };
  std::vector<double> xi(n);
  for (int i = 0; i < n; ++i) {
    xi[i] = (knot(i + 1) + knot(i + 2) + knot(i + 3)) / 3.0;
  }
  const double spacing2 = 1.0 / ((n - 1.0) * (n - 1.0));
  std::vector<std::array<double, 3>> rows;
  for (int i = 1; i + 1 < n; ++i) {
    const double before = xi[i] - xi[i - 1], after = xi[i + 1] - xi[i];
    const double minus = 2.0 * spacing2 / (before * (before + after));
    const double plus = 2.0 * spacing2 / (after * (before + after));
    rows.push_back({minus, -(minus + plus), plus});
  }
  return rows;
}

// Adds weight * D^T D to `normal` for the second differences D
// (SecondDifferences) of the nu x nv control grid along u and along v.
void AddSmoothness(int nu, int nv, double weight, Eigen::MatrixXd& normal) {
  auto add = [&](const std::array<int, 3>& index,
                 const std::array<double, 3>& coefficient) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        normal(index[a], index[b]) += weight * coefficient[a] * coefficient[b];
      }
    }
  };
  const std::vector<std::array<double, 3>> along_u = SecondDifferences(nu);
  const std::vector<std::array<double, 3>> along_v = SecondDifferences(nv);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      if (i > 0 && i + 1 < nu) {
        add({(i - 1) * nv + j, i * nv + j, (i + 1) * nv + j}, along_u[i - 1]);
      }
      if (j > 0 && j + 1 < nv) {
        add({i * nv + j - 1, i * nv + j, i * nv + j + 1}, along_v[j - 1]);
      }
    }
  }
}

// Weighted least-squares control values of the nu x nv grid of bases
// `bu`, `bv` for `fit`, into `control`. A point touches the 16 control
// values of its knot cell, so the normal equations are summed per cell
// (one 16 x 16 product of the cell's weighted basis values, a matrix
// product rather than a rank-one update per point) and scattered into the
// full system once.
absl::Status SolveControl(const SplineData& fit, const DirectionBasis& bu,
                          const DirectionBasis& bv, int nu, int nv,
                          const SurfaceModelOptions& options,
                          Eigen::VectorXf& control) {
  const int cells_u = nu - 3, cells_v = nv - 3, cells = cells_u * cells_v;
  const int n = static_cast<int>(fit.w.size());
  // Counting sort of the points by cell.
  std::vector<int> first(cells + 1, 0);
  for (int p = 0; p < n; ++p) ++first[bu.first[p] * cells_v + bv.first[p] + 1];
  for (int c = 0; c < cells; ++c) first[c + 1] += first[c];
  Eigen::Matrix<float, kOrder2, Eigen::Dynamic> a(kOrder2, n);
  Eigen::VectorXf b(n);
  std::vector<int> next(first.begin(), first.end() - 1);
  double total_weight = 0.0;
  for (int p = 0; p < n; ++p) {
    const int col = next[bu.first[p] * cells_v + bv.first[p]]++;
    const float root = std::sqrt(fit.weight[p]);
    // Entry i * 4 + j: bu_i bv_j.
    Eigen::Map<Eigen::Matrix4f>(a.col(col).data()) =
        (root * bv.value[p]) * bu.value[p].transpose();
    b(col) = root * fit.w[p];
    total_weight += fit.weight[p];
  }
  const int k = nu * nv;
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k);
  for (int su = 0; su < cells_u; ++su) {
    for (int sv = 0; sv < cells_v; ++sv) {
      const int cell = su * cells_v + sv;
      const int count = first[cell + 1] - first[cell];
      if (count == 0) continue;
      const auto block = a.middleCols(first[cell], count);
      const Matrix16f cell_normal = block * block.transpose();
      const Vector16f cell_rhs = block * b.segment(first[cell], count);
      for (int r = 0; r < kOrder2; ++r) {
        const int row = (su + r / kOrder) * nv + sv + r % kOrder;
        rhs(row) += cell_rhs(r);
        for (int c = 0; c < kOrder2; ++c) {
          const int col = (su + c / kOrder) * nv + sv + c % kOrder;
          normal(row, col) += cell_normal(r, c);
        }
      }
    }
  }
  // The objective is the weighted mean squared residual plus the
  // regularisers; times the total weight for the normal equations' scale.
  AddSmoothness(nu, nv, total_weight * options.smoothness_weight, normal);
  normal.diagonal().array() += total_weight * options.ridge_weight;
  Eigen::LLT<Eigen::MatrixXd> llt(normal);
  if (llt.info() != Eigen::Success) {
    return absl::InternalError(
        "surface_model: B-spline normal equations not positive definite");
  }
  const Eigen::VectorXd c = llt.solve(rhs);
  if (!c.allFinite()) {
    return absl::InternalError("surface_model: B-spline solution not finite");
  }
  control = c.cast<float>();
  return absl::OkStatus();
}

// What BSplineOf fits every grid from: the frame and both samples in its
// parameters, with their bases per direction and grid size tabulated on
// first use.
class SplineProblem {
 public:
  SplineProblem(const Samples& s, const BSplineSurface& frame,
                const SurfaceModelOptions& options)
      : s_(s), frame_(frame), options_(options) {
    const Eigen::Matrix3f to_local = frame.axes.transpose();
    const Eigen::Vector3f origin_in_axes = to_local * frame.origin;
    const Eigen::Vector2f extent = frame.max_uv - frame.min_uv;
    auto fill = [&](const std::vector<Eigen::Vector3f>& points,
                    const std::vector<float>& weights, bool held_out,
                    SplineData& data) {
      for (size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3f l = to_local * (points[i] - frame.origin);
        data.u.push_back((l.x() - frame.min_uv.x()) / extent.x());
        data.v.push_back((l.y() - frame.min_uv.y()) / extent.y());
        data.w.push_back(l.z());
        data.weight.push_back(weights[i]);
        if (held_out) {
          data.z.push_back(points[i].z());
          data.range2.push_back(points[i].squaredNorm());
          data.q.push_back(l + origin_in_axes);
        }
      }
    };
    fill(s.fit, s.fit_weight, false, fit_);
    fill(s.eval, s.eval_weight, true, eval_);
  }

  // The spline of grid nu x nv, with its description length.
  absl::StatusOr<SurfaceModel> Fit(int nu, int nv) {
    SurfaceModel model;
    model.kind = SurfaceKind::kBSpline;
    model.spline = frame_;
    model.spline.nu = nu;
    model.spline.nv = nv;
    FOVEA_RETURN_IF_ERROR(SolveControl(fit_, Basis(fit_u_, fit_.u, nu, 0),
                                       Basis(fit_v_, fit_.v, nv, 1), nu, nv,
                                       options_, model.spline.control));
    const DirectionBasis& bu = Basis(eval_u_, eval_.u, nu, 0);
    const DirectionBasis& bv = Basis(eval_v_, eval_.v, nv, 1);
    // As AddResidual, from the tabulated bases and in squares: with
    // t = (-dw/dx, -dw/dy, 1), distance^2 = (w - h)^2 / |t|^2 and
    // (p . n)^2 = (q . t)^2 / |t|^2.
    const float* control = model.spline.control.data();
    DataCode code(options_);
    for (size_t i = 0; i < eval_.w.size(); ++i) {
      // The 4 x 4 control block's rows weighted by the u basis (and by
      // its slopes), then dotted with the v basis (and its slopes).
      const float* block = control + bu.first[i] * nv + bv.first[i];
      Eigen::Vector4f along_u = Eigen::Vector4f::Zero();
      Eigen::Vector4f along_u_slope = Eigen::Vector4f::Zero();
      for (int r = 0; r < kOrder; ++r) {
        const Eigen::Map<const Eigen::Vector4f> row(block + r * nv);
        along_u += bu.value[i](r) * row;
        along_u_slope += bu.slope[i](r) * row;
      }
      const float h = along_u.dot(bv.value[i]);
      const Eigen::Vector3f t(-along_u_slope.dot(bv.value[i]),
                              -along_u.dot(bv.slope[i]), 1.0f);
      const float inverse_t2 = 1.0f / t.squaredNorm();
      const float q_dot_t = eval_.q[i].dot(t);
      const float residual = eval_.w[i] - h;
      code.AddSquared(eval_.z[i], eval_.range2[i],
                      q_dot_t * q_dot_t * inverse_t2,
                      residual * residual * inverse_t2, eval_.weight[i]);
    }
    code.Finish(s_.finite, nu * nv + kPlaneParameters, model);
    return model;
  }

 private:
  using Bases = std::array<std::optional<DirectionBasis>, kMaxCubicBasis + 1>;

  const DirectionBasis& Basis(Bases& cache, const std::vector<float>& t, int n,
                              int axis) {
    if (!cache[n]) {
      cache[n] = TabulateBasis(t, n, frame_.max_uv(axis) - frame_.min_uv(axis));
    }
    return *cache[n];
  }

  const Samples& s_;
  const BSplineSurface& frame_;
  const SurfaceModelOptions& options_;
  SplineData fit_, eval_;
  Bases fit_u_, fit_v_, eval_u_, eval_v_;
};

}  // namespace

absl::StatusOr<SurfaceModel> BSplineOf(const Samples& s,
                                       const SurfaceModelOptions& options,
                                       double ceiling) {
  if (s.finite < options.min_bspline_points) {
    return absl::InvalidArgumentError(absl::StrCat(
        "surface_model: a B-spline needs min_bspline_points (",
        options.min_bspline_points, ") finite points, got ", s.finite));
  }
  // The frame's extent covers both samples: held-out points are never
  // extrapolated to.
  BSplineSurface frame;
  frame.axes = s.axes;
  frame.origin = s.origin;
  frame.min_uv.setConstant(std::numeric_limits<float>::max());
  frame.max_uv.setConstant(std::numeric_limits<float>::lowest());
  const Eigen::Matrix3f to_local = s.axes.transpose();
  for (const auto* points : {&s.fit, &s.eval}) {
    for (const Eigen::Vector3f& p : *points) {
      const Eigen::Vector2f l = (to_local * (p - s.origin)).head<2>();
      frame.min_uv = frame.min_uv.cwiseMin(l);
      frame.max_uv = frame.max_uv.cwiseMax(l);
    }
  }
  if (!((frame.max_uv - frame.min_uv).minCoeff() >= kMinExtent)) {
    return absl::InvalidArgumentError(
        "surface_model: points span no area (collinear or coincident), no "
        "B-spline");
  }
  SplineProblem problem(s, frame, options);

  // The grid by MDL, greedily: from 4 x 4, add a row of control values
  // along u or along v while that shortens the description, up to
  // max_control per direction and fit points / points_per_control values.
  const int max_values =
      std::max(kMinCubicBasis * kMinCubicBasis,
               static_cast<int>(s.fit.size() / options.points_per_control));
  absl::StatusOr<SurfaceModel> best =
      problem.Fit(kMinCubicBasis, kMinCubicBasis);
  if (!best.ok()) return best.status();
  while (true) {
    const int nu = best->spline.nu, nv = best->spline.nv;
    const double bound = std::min(ceiling, best->description_length);
    absl::StatusOr<SurfaceModel> grown;
    for (const auto& [gu, gv] :
         {std::pair{nu + 1, nv}, std::pair{nu, nv + 1}}) {
      if (gu > options.max_control || gv > options.max_control ||
          gu * gv > max_values ||
          ParameterBits(s.finite, gu * gv + kPlaneParameters, options) >=
              bound) {
        continue;
      }
      FOVEA_ASSIGN_OR_RETURN(SurfaceModel m, problem.Fit(gu, gv));
      if (!grown.ok() || m.description_length < grown->description_length) {
        grown = std::move(m);
      }
    }
    if (!grown.ok() ||
        !(grown->description_length < best->description_length)) {
      break;
    }
    best = std::move(grown);
  }
  return best;
}

}  // namespace fovea::surface_model_internal
