// RandomSceneSpec: objects rest on the table or on a box, never
// interpenetrate, and a seed gives one spec (checked with geometry of its
// own, independent of the renderer's).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/synth/synth_scene.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synth/synth_test_util.h"

namespace fovea::synth {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

// --- Independent geometry for the physical-placement test. ---

// Whether local point p is inside the primitive shrunk by `eps`.
bool InsideLocal(const Primitive& prim, const Vector3f& p, float eps) {
  const Vector3f& h = prim.half_extents;
  const float r = prim.radius;
  switch (prim.shape) {
    case Shape::kBox:
      return (p.cwiseAbs() - h).maxCoeff() < -eps;
    case Shape::kCylinder:
      return std::abs(p.z()) < h.z() - eps && p.head<2>().norm() < r - eps;
    case Shape::kSphere:
      return p.norm() < r - eps;
    case Shape::kCone: {
      if (std::abs(p.z()) >= h.z() - eps) return false;
      return p.head<2>().norm() < r * (h.z() - p.z()) / (2 * h.z()) - eps;
    }
    case Shape::kCup:  // the solid it encloses, cavity included
      return std::abs(p.z()) < h.z() - eps && p.head<2>().norm() < r - eps;
    case Shape::kBowl:  // the outer sphere between foot and rim
      return std::abs(p.z()) < h.z() - eps &&
             (p - Vector3f(0, 0, h.z())).norm() < r - eps;
  }
  return false;
}

// Points filling the primitive on a grid, world frame.
std::vector<Vector3f> InteriorPoints(const Primitive& prim) {
  const Vector3f box =
      prim.shape == Shape::kBox
          ? prim.half_extents
          : Vector3f(prim.radius, prim.radius,
                     prim.shape == Shape::kSphere ? prim.radius
                                                  : prim.half_extents.z());
  constexpr int kN = 12;
  std::vector<Vector3f> points;
  for (int i = 0; i <= kN; ++i) {
    for (int j = 0; j <= kN; ++j) {
      for (int k = 0; k <= kN; ++k) {
        const Vector3f local = box.cwiseProduct(
            Vector3f(i, j, k) * (2.0f / kN) - Vector3f::Ones());
        // Surface points count (inflated by 10 um).
        if (InsideLocal(prim, local, -1e-5f)) {
          points.push_back(prim.pose * local);
        }
      }
    }
  }
  return points;
}

// Lowest world z of the primitive.
float LowestZ(const Primitive& prim) {
  const Vector3f c = prim.pose.translation();
  const Vector3f axis = prim.pose.linear().col(2);
  const float h = prim.half_extents.z();
  const float r = prim.radius;
  const float across = std::sqrt(std::max(0.0f, 1 - axis.z() * axis.z()));
  switch (prim.shape) {
    case Shape::kBox: {
      float lowest = 1e9f;
      for (int i = 0; i < 8; ++i) {
        const Vector3f corner(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
        lowest = std::min(
            lowest, (prim.pose * corner.cwiseProduct(prim.half_extents)).z());
      }
      return lowest;
    }
    case Shape::kCylinder:
      return c.z() - std::abs(axis.z()) * h - r * across;
    case Shape::kSphere:
      return c.z() - r;
    case Shape::kCup:
    case Shape::kBowl:  // both stand upright: the foot
      return c.z() - h;
    case Shape::kCone: {
      const float base = c.z() - axis.z() * h - r * across;
      return std::min(base, c.z() + axis.z() * h);
    }
  }
  return 0.0f;
}

TEST(RandomSceneSpecTest, ObjectsRestOnTableOrBoxAndDoNotInterpenetrate) {
  constexpr float kTol = 1e-4f;
  int total = 0, stacked = 0;
  std::set<Shape> shapes;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(seed);
    const SceneSpec spec = RandomSceneSpec(seed, RandomSceneOptions());
    ASSERT_TRUE(Validate(spec).ok());
    EXPECT_GE(spec.objects.size(), 2u);
    EXPECT_LE(spec.objects.size(), 6u);
    std::vector<std::vector<Vector3f>> interiors;
    for (const Primitive& p : spec.objects) {
      interiors.push_back(InteriorPoints(p));
      shapes.insert(p.shape);
    }
    for (size_t i = 0; i < spec.objects.size(); ++i) {
      const Primitive& p = spec.objects[i];
      ++total;
      // Household sizes: 2.5-15 cm in every dimension.
      const Vector3f size =
          2 * (p.shape == Shape::kBox ? p.half_extents
               : p.shape == Shape::kSphere
                   ? Vector3f::Constant(p.radius)
                   : Vector3f(p.radius, p.radius, p.half_extents.z()));
      EXPECT_GE(size.minCoeff(), 0.025f);
      EXPECT_LE(size.maxCoeff(), 0.15f);
      // Every point on the table rectangle and in front of the camera.
      for (const Vector3f& q : interiors[i]) {
        ASSERT_LE(std::abs(q.x()), spec.table_half_size.x());
        ASSERT_LE(std::abs(q.y()), spec.table_half_size.y());
        ASSERT_GE(q.z(), -kTol);
      }
      const Vector2f centre_px = Project(spec, p.pose.translation());
      EXPECT_TRUE(centre_px.x() > 0 && centre_px.x() < 640 &&
                  centre_px.y() > 0 && centre_px.y() < 480);
      // Resting: on the table, or on the top face of a level box with the
      // centre of mass above that face.
      const float lowest = LowestZ(p);
      if (std::abs(lowest) > kTol) {
        bool supported = false;
        for (const Primitive& s : spec.objects) {
          if (&s == &p || s.shape != Shape::kBox) continue;
          const bool level = std::abs(s.pose.linear().col(2).z()) > 1 - 1e-5f;
          const float top = s.pose.translation().z() + s.half_extents.z();
          const Vector3f local = s.pose.inverse() * p.pose.translation();
          supported |= level && std::abs(top - lowest) < kTol &&
                       std::abs(local.x()) <= s.half_extents.x() &&
                       std::abs(local.y()) <= s.half_extents.y();
        }
        EXPECT_TRUE(supported) << "object " << i << " floats at " << lowest;
        ++stacked;
      }
      // No point of one object inside another (1 mm tolerance).
      for (size_t j = 0; j < spec.objects.size(); ++j) {
        if (j == i) continue;
        const Primitive& o = spec.objects[j];
        const Eigen::Isometry3f to_local = o.pose.inverse();
        int inside = 0;
        for (const Vector3f& q : interiors[i]) {
          inside += InsideLocal(o, to_local * q, 1e-3f);
        }
        EXPECT_EQ(inside, 0) << "objects " << i << " and " << j;
      }
    }
  }
  EXPECT_GT(stacked, 0);  // stacking happens
  EXPECT_GT(total, 40 * 3);
  EXPECT_EQ(shapes.size(), 4u);  // all shapes occur
}

TEST(RandomSceneSpecTest, PilesRestOnTheTableOrABoxAndDoNotInterpenetrate) {
  constexpr float kTol = 1e-4f;
  std::set<Shape> shapes;
  int leaning = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE(seed);
    const SceneSpec spec = RandomSceneSpec(seed, PileOptions());
    ASSERT_TRUE(Validate(spec).ok());
    EXPECT_GE(spec.objects.size(), 8u);
    std::vector<std::vector<Vector3f>> interiors;
    for (const Primitive& p : spec.objects) {
      interiors.push_back(InteriorPoints(p));
      shapes.insert(p.shape);
    }
    for (size_t i = 0; i < spec.objects.size(); ++i) {
      const Primitive& p = spec.objects[i];
      const bool tilted = std::abs(p.pose.linear().col(2).z()) < 0.99f &&
                          p.shape == Shape::kBox;
      leaning += tilted;
      for (const Vector3f& q : interiors[i]) ASSERT_GE(q.z(), -kTol);
      if (!tilted && std::abs(LowestZ(p)) > kTol) {
        bool supported = false;
        for (const Primitive& s : spec.objects) {
          if (&s == &p || s.shape != Shape::kBox) continue;
          const bool level = std::abs(s.pose.linear().col(2).z()) > 1 - 1e-5f;
          const float top = s.pose.translation().z() + s.half_extents.z();
          supported |= level && std::abs(top - LowestZ(p)) < kTol;
        }
        EXPECT_TRUE(supported) << "object " << i << " floats";
      }
      for (size_t j = 0; j < spec.objects.size(); ++j) {
        if (j == i) continue;
        const Primitive& o = spec.objects[j];
        const Eigen::Isometry3f to_local = o.pose.inverse();
        int inside = 0;
        for (const Vector3f& q : interiors[i]) {
          inside += InsideLocal(o, to_local * q, 1e-3f);
        }
        EXPECT_EQ(inside, 0) << "objects " << i << " and " << j;
      }
    }
  }
  EXPECT_TRUE(shapes.count(Shape::kBowl) && shapes.count(Shape::kCup));
  EXPECT_GT(leaning, 0);
}

TEST(RandomSceneSpecTest, SameSeedSameSpec) {
  const SceneSpec a = RandomSceneSpec(11, RandomSceneOptions());
  const SceneSpec b = RandomSceneSpec(11, RandomSceneOptions());
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].pose.matrix(), b.objects[i].pose.matrix());
    EXPECT_EQ(a.objects[i].rgb, b.objects[i].rgb);
  }
  EXPECT_EQ(a.camera_pose.matrix(), b.camera_pose.matrix());
}

TEST(RandomSceneSpecTest, HonoursObjectCountBounds) {
  RandomSceneOptions options;
  options.min_objects = 1;
  options.max_objects = 1;
  EXPECT_EQ(RandomSceneSpec(5, options).objects.size(), 1u);
  options.min_objects = 0;
  options.max_objects = 0;
  EXPECT_TRUE(RandomSceneSpec(5, options).objects.empty());
}

}  // namespace
}  // namespace fovea::synth
