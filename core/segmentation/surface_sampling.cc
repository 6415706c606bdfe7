#include "core/segmentation/surface_sampling.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iterator>

#include "absl/strings/str_cat.h"

namespace fovea::surface_model_internal {
namespace {

// A plane needs three points.
constexpr int kMinPlanePoints = 3;

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

}  // namespace

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

}  // namespace fovea::surface_model_internal
