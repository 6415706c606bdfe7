#include "core/scene/hull_lookup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/scene/support_plane.h"

namespace fovea {
namespace {

// A horizontal plane y = 1 seen from above (normal -y, towards a camera at
// the origin), its plane coordinates (x, z) through the axes given.
SupportPlane PlaneWithHull(std::vector<Eigen::Vector2f> hull) {
  SupportPlane plane;
  plane.normal = -Eigen::Vector3f::UnitY();
  plane.d = 1.0f;
  plane.axis_u = Eigen::Vector3f::UnitX();
  plane.axis_v = Eigen::Vector3f::UnitZ();
  plane.hull = std::move(hull);
  return plane;
}

// A random convex polygon: points on an ellipse at sorted random angles,
// counter-clockwise in plane coordinates.
std::vector<Eigen::Vector2f> RandomHull(std::mt19937& rng) {
  std::uniform_real_distribution<float> angle(0.0f, 2.0f * M_PI);
  std::uniform_real_distribution<float> radius(0.2f, 1.5f);
  std::uniform_real_distribution<float> centre(-1.0f, 1.0f);
  std::uniform_int_distribution<int> count(3, 60);
  const float rx = radius(rng), ry = radius(rng);
  const Eigen::Vector2f c(centre(rng), 1.5f + centre(rng));
  std::vector<float> angles(count(rng));
  for (float& a : angles) a = angle(rng);
  std::sort(angles.begin(), angles.end());
  std::vector<Eigen::Vector2f> hull;
  for (float a : angles) {
    hull.push_back(c + Eigen::Vector2f(rx * std::cos(a), ry * std::sin(a)));
  }
  return hull;
}

TEST(HullLookupTest, UnitSquareInsideOutsideAndMargin) {
  const SupportPlane plane =
      PlaneWithHull({{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}});
  const HullLookup plain(plane, 0.0f);
  const HullLookup margin(plane, 0.3f);
  EXPECT_TRUE(plain.Contains({0.5f, 1.0f, 0.5f}));   // the centre
  EXPECT_TRUE(margin.Contains({0.5f, 1.0f, 0.5f}));  // 0.5 from every edge
  EXPECT_TRUE(plain.Contains({0.1f, 1.0f, 0.5f}));
  EXPECT_FALSE(margin.Contains({0.1f, 1.0f, 0.5f}));  // 0.1 from an edge
  EXPECT_FALSE(plain.Contains({1.2f, 1.0f, 0.5f}));
  EXPECT_FALSE(plain.Contains({-5.0f, 1.0f, 30.0f}));  // far off the grid
  // The plane's height does not matter: the point is projected.
  EXPECT_TRUE(plain.Contains({0.5f, -3.0f, 0.5f}));
  EXPECT_FALSE(plain.Contains({NAN, 1.0f, 0.5f}));
  EXPECT_FALSE(HullLookup(PlaneWithHull({{0, 0}, {1, 0}}), 0.0f)
                   .Contains({0.5f, 1.0f, 0.0f}));
}

// The point of the lookup: never a different answer from the edge-by-edge
// test, here on points spread over and around random hulls and points a
// hair from their edges and vertices.
TEST(HullLookupTest, AgreesWithTheEdgeByEdgeTestEverywhere) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> spread(-3.0f, 5.0f);
  std::uniform_real_distribution<float> hair(-2e-5f, 2e-5f);
  std::uniform_real_distribution<float> along(0.0f, 1.0f);
  int inside = 0, checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const SupportPlane plane = PlaneWithHull(RandomHull(rng));
    for (const float margin : {0.0f, 0.02f, 0.3f}) {
      const HullLookup lookup(plane, margin);
      std::vector<Eigen::Vector3f> points;
      for (int k = 0; k < 4000; ++k) {
        points.emplace_back(spread(rng), 1.0f, spread(rng) - 1.0f);
      }
      for (size_t e = 0; e < plane.hull.size(); ++e) {
        const Eigen::Vector2f a = plane.hull[e];
        const Eigen::Vector2f b = plane.hull[(e + 1) % plane.hull.size()];
        for (int k = 0; k < 20; ++k) {
          const Eigen::Vector2f q = a + along(rng) * (b - a);
          points.emplace_back(q.x() + hair(rng), 1.0f, q.y() + hair(rng));
        }
        points.emplace_back(a.x(), 1.0f, a.y());
      }
      for (const Eigen::Vector3f& p : points) {
        const bool expected = plane.ProjectsInsideHull(p, margin);
        ASSERT_EQ(lookup.Contains(p), expected)
            << "trial " << trial << " margin " << margin << " point "
            << p.transpose();
        inside += expected;
        ++checked;
      }
    }
  }
  // Both answers were exercised.
  EXPECT_GT(inside, checked / 50);
  EXPECT_LT(inside, checked - checked / 50);
}

}  // namespace
}  // namespace fovea
