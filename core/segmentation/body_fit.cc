#include "core/segmentation/body_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/base/status_macros.h"

namespace fovea {
namespace {

// OnOneBody refines a cylinder into a cone, and a body into one with a
// wall, only when the body misses by at most this many times the allowed
// rms.
constexpr float kRefineRms = 4.0f;

// At most `limit` of `points`, evenly strided, appended to `out`.
void Sample(const std::vector<Eigen::Vector3f>& points, int limit,
            std::vector<Eigen::Vector3f>& out) {
  const size_t stride =
      std::max<size_t>(1, (points.size() + limit - 1) / std::max(1, limit));
  for (size_t i = 0; i < points.size(); i += stride) out.push_back(points[i]);
}

// Two unit axes normal to the unit `n` and to each other.
std::pair<Eigen::Vector3d, Eigen::Vector3d> AxesAcross(
    const Eigen::Vector3d& n) {
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9
                                     ? Eigen::Vector3d::UnitX()
                                     : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = n.cross(helper).normalized();
  return {u, n.cross(u)};
}

// Gauss-Newton on `n` residuals from `x`: residual(i, x) is the i-th
// residual and its gradient in x. At most 8 steps, ending at a step under
// 1e-7; the sum of squared residuals at the solution, nullopt where a step
// is not finite.
template <int P, typename Residual>
std::optional<double> GaussNewton(Eigen::Matrix<double, P, 1>& x, size_t n,
                                  const Residual& residual) {
  using Vector = Eigen::Matrix<double, P, 1>;
  using Matrix = Eigen::Matrix<double, P, P>;
  for (int iteration = 0; iteration < 8; ++iteration) {
    Matrix jtj = Matrix::Zero();
    Vector jte = Vector::Zero();
    for (size_t i = 0; i < n; ++i) {
      const auto [e, j] = residual(i, x);
      jtj += j * j.transpose();
      jte += j * e;
    }
    const Vector step = jtj.ldlt().solve(-jte);
    if (!step.allFinite()) return std::nullopt;
    x += step;
    if (step.norm() < 1e-7) break;
  }
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double e = residual(i, x).first;
    sum += e * e;
  }
  if (!std::isfinite(sum)) return std::nullopt;
  return sum;
}

// The least-squares solution of |q|^2 + g . q + f = 0 over `q` (rows of
// dimension n): the centre -g / 2 and radius, with the geometric rms.
template <int N>
std::optional<BodyFit> FitRound(
    const std::vector<Eigen::Matrix<double, N, 1>>& q) {
  if (static_cast<int>(q.size()) < N + 1) return std::nullopt;
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (const auto& p : q) mean += p;
  mean /= static_cast<double>(q.size());
  // Centred, for conditioning.
  Eigen::MatrixXd a(q.size(), N + 1);
  Eigen::VectorXd b(q.size());
  for (size_t i = 0; i < q.size(); ++i) {
    const Eigen::Matrix<double, N, 1> p = q[i] - mean;
    a.row(i).head<N>() = p.transpose();
    a(i, N) = 1.0;
    b(i) = -p.squaredNorm();
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  if (!x.allFinite()) return std::nullopt;
  const Eigen::Matrix<double, N, 1> center = -0.5 * x.template head<N>();
  const double r2 = center.squaredNorm() - x(N);
  if (!(r2 > 0.0)) return std::nullopt;
  const double r = std::sqrt(r2);
  double sum = 0.0;
  for (const auto& p : q) {
    const double e = (p - mean - center).norm() - r;
    sum += e * e;
  }
  BodyFit fit;
  fit.radius = static_cast<float>(r);
  fit.rms = static_cast<float>(std::sqrt(sum / static_cast<double>(q.size())));
  const Eigen::Matrix<double, N, 1> c = center + mean;
  for (int i = 0; i < N; ++i) fit.center[i] = static_cast<float>(c[i]);
  return fit;
}

}  // namespace

absl::Status Validate(const BodyFitOptions& o) {
  if (o.min_points < 4) {
    return absl::InvalidArgumentError("body_join.min_points must be >= 4");
  }
  if (!(o.min_radius_m > 0.0f) || !(o.max_radius_m > o.min_radius_m)) {
    return absl::InvalidArgumentError(
        "body_join radii must satisfy 0 < min_radius_m < max_radius_m");
  }
  if (!(o.wall_m >= 0.0f) || !(o.sigma0_m >= 0.0f) ||
      !(o.sigma_per_z2 >= 0.0f) ||
      !(o.wall_m + o.sigma0_m + o.sigma_per_z2 > 0.0f)) {
    return absl::InvalidArgumentError(
        "body_join: wall_m, sigma0_m and sigma_per_z2 must be >= 0, not all "
        "0");
  }
  if (o.max_fit_points < 4) {
    return absl::InvalidArgumentError("body_join.max_fit_points must be >= 4");
  }
  if (!(o.max_taper >= 0.0f)) {
    return absl::InvalidArgumentError("body_join.max_taper must be >= 0");
  }
  if (!(o.max_wall_m >= 0.0f)) {
    return absl::InvalidArgumentError("body_join.max_wall_m must be >= 0");
  }
  return absl::OkStatus();
}

double PlaneRms(std::vector<Eigen::Vector3f>::const_iterator first,
                std::vector<Eigen::Vector3f>::const_iterator last) {
  const double n = static_cast<double>(last - first);
  if (n < 3.0) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (auto p = first; p != last; ++p) mean += p->cast<double>();
  mean /= n;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (auto p = first; p != last; ++p) {
    const Eigen::Vector3d d = p->cast<double>() - mean;
    covariance += d * d.transpose();
  }
  covariance /= n;
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                              covariance, Eigen::EigenvaluesOnly)
                              .eigenvalues()(0);
  return std::sqrt(std::max(smallest, 0.0));
}

std::optional<BodyFit> FitSphere(const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector3d> q;
  q.reserve(points.size());
  for (const Eigen::Vector3f& p : points) q.push_back(p.cast<double>());
  return FitRound<3>(q);
}

std::optional<BodyFit> FitUprightCylinder(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& up) {
  const auto [u, v] = AxesAcross(up.cast<double>().normalized());
  std::vector<Eigen::Vector2d> q;
  q.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d d = p.cast<double>();
    q.emplace_back(u.dot(d), v.dot(d));
  }
  std::optional<BodyFit> fit = FitRound<2>(q);
  if (!fit.has_value()) return fit;
  // The centre back in 3D, on the plane through the origin normal to up.
  const Eigen::Vector3d c = u * fit->center.x() + v * fit->center.y();
  fit->center = c.cast<float>();
  return fit;
}

namespace {

// The cone of axis `up` through `points` from `cylinder`, their
// FitUprightCylinder. With P = 5, the points from index `wall_from` on lie
// on a second cone of the same axis and taper, its radius the fit's `wall`
// off the first's (a vessel's inside and outside).
template <int P>
std::optional<BodyFit> ConeFromCylinder(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& up,
    const BodyFit& cylinder, size_t wall_from = 0) {
  static_assert(P == 4 || P == 5);
  if (points.size() < P + 1) return std::nullopt;
  const Eigen::Vector3d n = up.cast<double>().normalized();
  const Eigen::Vector3d center = cylinder.center.cast<double>();
  const auto [u, v] = AxesAcross(n);
  // Each point: its offset from the cylinder's axis across `up` and its
  // height along it, centred.
  std::vector<Eigen::Vector3d> across;
  std::vector<double> height;
  across.reserve(points.size());
  height.reserve(points.size());
  double mean_h = 0.0;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d d = p.cast<double>() - center;
    height.push_back(n.dot(d));
    mean_h += height.back();
    across.push_back(d - n * height.back());
  }
  mean_h /= static_cast<double>(points.size());
  for (double& h : height) h -= mean_h;
  // Gauss-Newton on the distance to the cone: the axis' offset (two
  // coordinates across `up`), the radius at the mean height, the taper and
  // the wall, from the cylinder.
  using Vector = Eigen::Matrix<double, P, 1>;
  Vector x = Vector::Zero();
  x(2) = cylinder.radius;
  const std::optional<double> sum =
      GaussNewton<P>(x, across.size(), [&](size_t i, const Vector& at) {
        const Eigen::Vector3d d = across[i] - u * at(0) - v * at(1);
        const double r = std::max(d.norm(), 1e-9);
        Vector j;
        j.template head<4>() << -u.dot(d) / r, -v.dot(d) / r, -1.0, -height[i];
        double e = r - (at(2) + at(3) * height[i]);
        if constexpr (P == 5) {
          const double in_wall = i >= wall_from ? 1.0 : 0.0;
          e -= at(4) * in_wall;
          j(4) = -in_wall;
        }
        return std::pair{e, j};
      });
  if (!sum.has_value() || !(x(2) > 0.0)) return std::nullopt;
  BodyFit cone;
  cone.center =
      (center + u * x(0) + v * x(1) + n * mean_h).template cast<float>();
  cone.radius = static_cast<float>(x(2));
  cone.taper = static_cast<float>(x(3));
  if constexpr (P == 5) cone.wall = static_cast<float>(x(4));
  cone.rms =
      static_cast<float>(std::sqrt(*sum / static_cast<double>(across.size())));
  return cone;
}

// The sphere through `points` from `sphere`, their FitSphere, the points
// from index `wall_from` on on a second sphere of the same centre, its
// radius the fit's `wall` off the first's (a bowl's inside and outside).
std::optional<BodyFit> WalledSphere(const std::vector<Eigen::Vector3f>& points,
                                    const BodyFit& sphere, size_t wall_from) {
  if (points.size() < 6) return std::nullopt;
  Eigen::Matrix<double, 5, 1> x;
  x << sphere.center.cast<double>(), sphere.radius, 0.0;
  const std::optional<double> sum = GaussNewton<5>(
      x, points.size(), [&](size_t i, const Eigen::Matrix<double, 5, 1>& at) {
        const Eigen::Vector3d d = points[i].cast<double>() - at.head<3>();
        const double r = std::max(d.norm(), 1e-9);
        const double in_wall = i >= wall_from ? 1.0 : 0.0;
        Eigen::Matrix<double, 5, 1> j;
        j << -d / r, -1.0, -in_wall;
        return std::pair{r - at(3) - at(4) * in_wall, j};
      });
  if (!sum.has_value() || !(x(3) > 0.0)) return std::nullopt;
  BodyFit fit;
  fit.center = x.head<3>().cast<float>();
  fit.radius = static_cast<float>(x(3));
  fit.wall = static_cast<float>(x(4));
  fit.rms =
      static_cast<float>(std::sqrt(*sum / static_cast<double>(points.size())));
  return fit;
}

}  // namespace

std::optional<BodyFit> FitUprightCone(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& up) {
  const std::optional<BodyFit> cylinder = FitUprightCylinder(points, up);
  if (!cylinder.has_value()) return std::nullopt;
  return ConeFromCylinder<4>(points, up, *cylinder);
}

bool OnOneBody(const std::vector<Eigen::Vector3f>& a,
               const std::vector<Eigen::Vector3f>& b, const Eigen::Vector3f& up,
               const BodyFitOptions& options) {
  if (static_cast<int>(a.size()) < options.min_points ||
      static_cast<int>(b.size()) < options.min_points) {
    return false;
  }
  std::vector<Eigen::Vector3f> both;
  both.reserve(2 * options.max_fit_points);
  Sample(a, options.max_fit_points, both);
  const size_t b_from = both.size();
  Sample(b, options.max_fit_points, both);
  float z = 0.0f;
  for (const Eigen::Vector3f& p : both) z += p.z();
  z /= static_cast<float>(both.size());
  const float max_rms = std::hypot(
      options.wall_m, options.sigma0_m + options.sigma_per_z2 * z * z);
  const auto fits = [&](const std::optional<BodyFit>& fit) {
    return fit.has_value() && fit->radius >= options.min_radius_m &&
           fit->radius <= options.max_radius_m && fit->rms <= max_rms;
  };
  // Fits farther off than this are not refined.
  const auto near = [&](const std::optional<BodyFit>& fit) {
    return fit.has_value() && fit->rms <= kRefineRms * max_rms;
  };
  const std::optional<BodyFit> sphere = FitSphere(both);
  if (fits(sphere)) return true;
  const std::optional<BodyFit> cylinder = FitUprightCylinder(both, up);
  if (fits(cylinder)) return true;
  // A cone within max_taper is near a cylinder: a 10 cm mug of taper 0.15
  // misses its cylinder by 4 mm rms.
  const bool cones = options.max_taper > 0.0f && near(cylinder);
  if (cones) {
    const std::optional<BodyFit> cone =
        ConeFromCylinder<4>(both, up, *cylinder);
    if (fits(cone) && std::abs(cone->taper) <= options.max_taper) return true;
  }
  // One body's inside and outside, a wall apart; each of them curved (no
  // plane holds it within the noise): the second radius would otherwise
  // let a box's face beside a bowl pass for its other side.
  if (!(options.max_wall_m > 0.0f) ||
      PlaneRms(both.begin(), both.begin() + b_from) <= max_rms ||
      PlaneRms(both.begin() + b_from, both.end()) <= max_rms) {
    return false;
  }
  const auto fits_walled = [&](const std::optional<BodyFit>& fit) {
    return fits(fit) && std::abs(fit->wall) <= options.max_wall_m;
  };
  if (near(sphere) && fits_walled(WalledSphere(both, *sphere, b_from))) {
    return true;
  }
  if (cones) {
    const std::optional<BodyFit> walled =
        ConeFromCylinder<5>(both, up, *cylinder, b_from);
    if (fits_walled(walled) && std::abs(walled->taper) <= options.max_taper) {
      return true;
    }
  }
  return false;
}

}  // namespace fovea
