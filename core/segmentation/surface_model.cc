#include "core/segmentation/surface_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/segmentation/cubic_bspline.h"

namespace fovea {
namespace {

constexpr int kOrder = kCubicOrder;
constexpr int kOrder2 = kOrder * kOrder;
// A plane needs three points.
constexpr int kMinPlanePoints = 3;
// Points spanning less than this along the first or second principal axis
// span no area (no (u, v) parameterisation), metres.
constexpr float kMinExtent = 1e-6f;
// Depths and cosines are floored at these in the noise model (a point at
// the camera, a surface seen edge-on).
constexpr float kMinDepth = 1e-3f;  // metres
constexpr float kMinCos = 1e-2f;
// Parameters of a plane (3 degrees of freedom); a spline has its control
// values plus the same three for its frame's w = 0 plane.
constexpr int kPlaneParameters = 3;
constexpr double kLn2 = 0.69314718055994530942;
// Bits of a Gaussian residual per squared sigma: 1 / (2 ln 2).
constexpr double kBitsPerSquaredSigma = 1.0 / (2.0 * kLn2);

using Matrix16f = Eigen::Matrix<float, kOrder2, kOrder2>;
using Vector16f = Eigen::Matrix<float, kOrder2, 1>;

// w(u, v) of `spline` and, unless null, its gradient (dw/du, dw/dv).
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

// Whether all of p's coordinates are finite: their sum is (x - x is 0 for
// finite x, NaN for NaN and infinities; metric points do not overflow
// float), with one comparison and no branch per point.
bool IsFinite(const Eigen::Vector3f& p) {
  const float sum = p.x() + p.y() + p.z();
  return sum - sum == 0.0f;
}

// Two disjoint samples of `count` of `size` positions (size >= 2 count),
// stratified: cell k of `count` equal cells gives one position from its
// first half to `first` and one from its second half to `second`, each at
// an offset frac(k * golden ratio) of its half (a low-discrepancy jitter:
// a regular stride would alias with the rows of a patch in raster order,
// taking the same few columns from every row).
void StratifiedPair(int size, int count, std::vector<int>& first,
                    std::vector<int>& second) {
  constexpr double kGoldenFraction = 0.6180339887498949;
  const double cell = static_cast<double>(size) / count;
  for (int k = 0; k < count; ++k) {
    const int lo = static_cast<int>(k * cell);
    const int hi = std::min(size, static_cast<int>((k + 1) * cell));
    const int mid = (lo + hi) / 2;
    const double jitter = std::fmod(k * kGoldenFraction, 1.0);
    first.push_back(lo + static_cast<int>(jitter * (mid - lo)));
    second.push_back(mid + static_cast<int>(jitter * (hi - mid)));
  }
}

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

// Adds the finite points of one stratum to `s`: all of them to both
// samples when there are fewer than min_bspline_points (too few to
// split), else alternate points to each (up to 2 * max_fit_points), else
// max_fit_points to each (StratifiedPair).
void AddStratum(const std::vector<Eigen::Vector3f>& points, int stratum,
                const SurfaceModelOptions& options, Samples& s) {
  std::vector<Eigen::Vector3f> finite;
  const std::vector<Eigen::Vector3f>* source = &points;
  const int n =
      static_cast<int>(std::count_if(points.begin(), points.end(), IsFinite));
  if (n < static_cast<int>(points.size())) {
    finite.reserve(n);
    std::copy_if(points.begin(), points.end(), std::back_inserter(finite),
                 IsFinite);
    source = &finite;
  }
  s.finite += n;
  s.stratum_finite.push_back(n);
  auto add = [&](const std::vector<int>& fit, const std::vector<int>& eval) {
    for (const int i : fit) {
      s.fit.push_back((*source)[i]);
      s.fit_weight.push_back(static_cast<float>(n) / fit.size());
    }
    for (const int i : eval) {
      s.eval.push_back((*source)[i]);
      s.eval_weight.push_back(static_cast<float>(n) / eval.size());
      s.eval_stratum.push_back(stratum);
    }
  };
  if (n == 0) return;
  if (n < options.min_bspline_points) {
    std::vector<int> all(n);
    for (int i = 0; i < n; ++i) all[i] = i;
    add(all, all);
  } else if (n <= 2 * options.max_fit_points) {
    std::vector<int> even, odd;
    for (int i = 0; i < n; ++i) (i % 2 == 0 ? even : odd).push_back(i);
    add(even, odd);
  } else {
    std::vector<int> fit, eval;
    StratifiedPair(n, options.max_fit_points, fit, eval);
    add(fit, eval);
  }
}

// Principal axes of the weighted `points` (at least one): x, y, w by
// decreasing variance, w towards the camera, right-handed; the identity
// when the eigen decomposition fails.
void PrincipalFrame(const std::vector<Eigen::Vector3f>& points,
                    const std::vector<float>& weights, Eigen::Matrix3f& axes,
                    Eigen::Vector3f& origin) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    sum += weights[i] * points[i].cast<double>();
    total += weights[i];
  }
  const Eigen::Vector3d c = sum / total;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d q = points[i].cast<double>() - c;
    cov.noalias() += weights[i] * q * q.transpose();
  }
  cov /= total;
  origin = c.cast<float>();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success || !eig.eigenvectors().allFinite()) {
    axes.setIdentity();
    return;
  }
  // Eigenvalues ascending: column 2 has the largest variance.
  const Eigen::Vector3d x = eig.eigenvectors().col(2).normalized();
  Eigen::Vector3d w = eig.eigenvectors().col(0).normalized();
  if (w.dot(c) > 0.0) w = -w;
  const Eigen::Vector3d y = w.cross(x).normalized();
  axes.col(0) = x.cast<float>();
  axes.col(1) = y.cast<float>();
  axes.col(2) = w.cast<float>();
}

absl::StatusOr<Samples> BuildSamples(
    std::initializer_list<const std::vector<Eigen::Vector3f>*> strata,
    const SurfaceModelOptions& options) {
  Samples s;
  int stratum = 0;
  for (const std::vector<Eigen::Vector3f>* points : strata) {
    AddStratum(*points, stratum++, options, s);
  }
  if (s.finite < kMinPlanePoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface_model: points must hold at least ",
                     kMinPlanePoints, " finite points, got ", s.finite));
  }
  PrincipalFrame(s.fit, s.fit_weight, s.axes, s.origin);
  return s;
}

// Rissanen's parameter bits for `parameters` parameters of N points.
double ParameterBits(int points, int parameters,
                     const SurfaceModelOptions& options) {
  return options.kappa_parameter *
         std::log2(static_cast<double>(std::max(points, 2))) * parameters;
}

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
                 float weight, DataCode& code) {
  if (model.kind == SurfaceKind::kPlane) {
    const Eigen::Vector3f n = model.plane.head<3>();
    code.Add(p, n.dot(p) + model.plane.w(), n, weight);
    return;
  }
  const BSplineSurface& spline = model.spline;
  const Eigen::Vector3f l = spline.axes.transpose() * (p - spline.origin);
  const Eigen::Vector2f extent = spline.max_uv - spline.min_uv;
  const Eigen::Vector2f uv =
      (l.head<2>() - spline.min_uv).cwiseQuotient(extent);
  Eigen::Vector2f gradient;
  const float h = HeightAndGradient(spline, uv.x(), uv.y(), &gradient);
  const Eigen::Vector3f t(-gradient.x() / extent.x(),
                          -gradient.y() / extent.y(), 1.0f);
  const float length = t.norm();
  code.Add(p, (l.z() - h) / length, spline.axes * (t / length), weight);
}

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

// The B-spline of `s`, its grid chosen by MDL. Grids whose parameter bits
// alone reach `ceiling` are not tried beyond 4 x 4 (they could not be
// chosen over a model of that description length).
absl::StatusOr<SurfaceModel> BSplineOf(
    const Samples& s, const SurfaceModelOptions& options,
    double ceiling = std::numeric_limits<double>::infinity()) {
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
