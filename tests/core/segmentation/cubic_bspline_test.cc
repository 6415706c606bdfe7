#include "core/segmentation/cubic_bspline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

namespace fovea {
namespace {

TEST(CubicBSplineTest, TablesMatchTheCoxDeBoorRecursion) {
  for (int n = kMinCubicBasis; n <= kMaxCubicBasis; ++n) {
    for (int i = 0; i <= 1000; ++i) {
      const double t = i / 1000.0;
      std::array<float, 4> b;
      std::array<double, 4> reference;
      const int first = CubicBSplineBasis(static_cast<float>(t), n, b.data());
      ASSERT_EQ(first, CubicBSplineBasisReference(t, n, reference.data()));
      ASSERT_GE(first, 0);
      ASSERT_LE(first, n - 4);
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(b[k], reference[k], 2e-6) << n << " " << t << " " << k;
      }
    }
  }
}

TEST(CubicBSplineTest, PartitionOfUnityAndLinearPrecision) {
  // Sum_i B_i(t) = 1 and, with the Greville abscissae xi_i = (knot_{i+1} +
  // knot_{i+2} + knot_{i+3}) / 3, sum_i xi_i B_i(t) = t.
  for (int n = kMinCubicBasis; n <= kMaxCubicBasis; ++n) {
    const int spans = n - 3;
    auto knot = [spans](int i) {
      return std::clamp(i - 3, 0, spans) / static_cast<double>(spans);
    };
    for (int i = 0; i <= 200; ++i) {
      const float t = i / 200.0f;
      std::array<float, 4> b, db;
      const int first = CubicBSplineBasis(t, n, b.data(), db.data());
      double sum = 0.0, linear = 0.0, slope_sum = 0.0, slope_linear = 0.0;
      for (int k = 0; k < 4; ++k) {
        const int j = first + k;
        const double xi = (knot(j + 1) + knot(j + 2) + knot(j + 3)) / 3.0;
        EXPECT_GE(b[k], -1e-6f);
        sum += b[k];
        linear += xi * b[k];
        slope_sum += db[k];
        slope_linear += xi * db[k];
      }
      EXPECT_NEAR(sum, 1.0, 1e-6) << n << " " << t;
      EXPECT_NEAR(linear, t, 1e-6) << n << " " << t;
      // Their derivatives: of 1 and of t.
      EXPECT_NEAR(slope_sum, 0.0, 1e-4) << n << " " << t;
      EXPECT_NEAR(slope_linear, 1.0, 1e-4) << n << " " << t;
    }
  }
}

TEST(CubicBSplineTest, FourFunctionsAreTheBernsteinPolynomials) {
  const float t = 0.3f, s = 1.0f - t;
  std::array<float, 4> b;
  EXPECT_EQ(CubicBSplineBasis(t, 4, b.data()), 0);
  EXPECT_NEAR(b[0], s * s * s, 1e-6f);
  EXPECT_NEAR(b[1], 3 * s * s * t, 1e-6f);
  EXPECT_NEAR(b[2], 3 * s * t * t, 1e-6f);
  EXPECT_NEAR(b[3], t * t * t, 1e-6f);
}

TEST(CubicBSplineTest, ParametersOutsideAreClamped) {
  std::array<float, 4> below, zero, above, one;
  EXPECT_EQ(CubicBSplineBasis(-0.5f, 7, below.data()),
            CubicBSplineBasis(0.0f, 7, zero.data()));
  EXPECT_EQ(below, zero);
  EXPECT_EQ(CubicBSplineBasis(1.5f, 7, above.data()), 3);
  EXPECT_EQ(CubicBSplineBasis(1.0f, 7, one.data()), 3);
  EXPECT_EQ(above, one);
  EXPECT_NEAR(one[3], 1.0f, 1e-6f);  // clamped ends interpolate
  EXPECT_NEAR(zero[0], 1.0f, 1e-6f);
}

}  // namespace
}  // namespace fovea
