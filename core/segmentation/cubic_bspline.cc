#include "core/segmentation/cubic_bspline.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <vector>

#include "core/base/check.h"

namespace fovea {
namespace {

// The span of t and t in span units (x in [s, s + 1]).
int SpanOf(double t, int n, double& x) {
  const int spans = n - 3;
  x = std::clamp(t, 0.0, 1.0) * spans;
  return std::min(static_cast<int>(x), spans - 1);
}

// The 4 functions non-zero on span s at x in [s, s + 1] (span units: knot
// i is clamp(i - 3, 0, spans)): algorithm A2.2 with knot span index s + 3.
void DeBoor(double x, int s, int spans, double* b) {
  auto knot = [spans](int i) {
    return static_cast<double>(std::clamp(i - 3, 0, spans));
  };
  const int i = s + 3;
  double left[kCubicOrder], right[kCubicOrder];
  b[0] = 1.0;
  for (int j = 1; j < kCubicOrder; ++j) {
    left[j] = x - knot(i + 1 - j);
    right[j] = knot(i + j) - x;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = b[r] / (right[r + 1] + left[j - r]);
      b[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    b[j] = saved;
  }
}

// Per n and span s, row k holds the coefficients of 1, tau, tau^2, tau^3
// of B_{s + k} in the span's local coordinate tau = x - s: the cubic
// through 4 samples of DeBoor, which it is exactly.
class SpanPolynomials {
 public:
  static const SpanPolynomials& Get() {
    static const SpanPolynomials* tables = new SpanPolynomials();
    return *tables;
  }
  const Eigen::Matrix4f& Of(int n, int s) const { return tables_[n][s]; }

 private:
  SpanPolynomials() {
    Eigen::Matrix4d vandermonde;
    for (int j = 0; j < kCubicOrder; ++j) {
      const double tau = j / 3.0;
      vandermonde.row(j) << 1.0, tau, tau * tau, tau * tau * tau;
    }
    const Eigen::Matrix4d inverse = vandermonde.inverse();
    for (int n = kMinCubicBasis; n <= kMaxCubicBasis; ++n) {
      for (int s = 0; s < n - 3; ++s) {
        Eigen::Matrix4d values;  // row j: the 4 functions at sample j
        for (int j = 0; j < kCubicOrder; ++j) {
          double b[kCubicOrder];
          DeBoor(s + j / 3.0, s, n - 3, b);
          values.row(j) = Eigen::Map<const Eigen::RowVector4d>(b);
        }
        tables_[n].push_back((inverse * values).transpose().cast<float>());
      }
    }
  }
  std::array<std::vector<Eigen::Matrix4f>, kMaxCubicBasis + 1> tables_;
};

}  // namespace

int CubicBSplineBasis(float t, int n, float* b, float* db) {
  FOVEA_CHECK(n >= kMinCubicBasis && n <= kMaxCubicBasis);
  const int spans = n - 3;
  const float x = std::clamp(t, 0.0f, 1.0f) * static_cast<float>(spans);
  const int s = std::min(static_cast<int>(x), spans - 1);
  const float tau = x - static_cast<float>(s);
  const Eigen::Matrix4f& m = SpanPolynomials::Get().Of(n, s);
  Eigen::Map<Eigen::Vector4f> values(b);
  values.noalias() = m * Eigen::Vector4f(1.0f, tau, tau * tau, tau * tau * tau);
  if (db != nullptr) {
    // d/dt = spans * d/dtau.
    const float k = static_cast<float>(spans);
    Eigen::Map<Eigen::Vector4f> slopes(db);
    slopes.noalias() =
        m * Eigen::Vector4f(0.0f, k, 2.0f * k * tau, 3.0f * k * tau * tau);
  }
  return s;
}

int CubicBSplineBasisReference(double t, int n, double* b) {
  FOVEA_CHECK(n >= kMinCubicBasis && n <= kMaxCubicBasis);
  double x = 0.0;
  const int s = SpanOf(t, n, x);
  DeBoor(x, s, n - 3, b);
  return s;
}

}  // namespace fovea
