// Bowls and cups: hollow primitives whose insides a ray can see.

#include <gtest/gtest.h>

#include <cmath>

#include "core/synth/raycast.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using Eigen::Vector3f;

Primitive Hollow(Shape shape, float radius, float half_height, float wall) {
  Primitive p;
  p.shape = shape;
  p.radius = radius;
  p.half_extents = Vector3f(radius, radius, half_height);
  p.thickness = wall;
  p.pose.translation() = Vector3f(0.0f, 0.0f, half_height);  // on z = 0
  return p;
}

TEST(HollowTest, ACupSeenFromAboveShowsItsInsideBottom) {
  // 4 cm radius, 10 cm tall, 4 mm walls: looking straight down the axis the
  // ray meets the inside bottom 4 mm above the foot.
  const Primitive cup = Hollow(Shape::kCup, 0.04f, 0.05f, 0.004f);
  const std::optional<RayHit> hit = IntersectPrimitive(
      cup, Vector3f(0, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(1.0f - hit->t, 0.004f, 1e-5f);
  EXPECT_GT(hit->normal.z(), 0.99f);
  // Through the rim annulus (between 36 and 40 mm from the axis).
  const std::optional<RayHit> rim = IntersectPrimitive(
      cup, Vector3f(0.038f, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(rim.has_value());
  EXPECT_NEAR(1.0f - rim->t, 0.1f, 1e-5f);
  // From the side, level with its middle: the outer wall at 4 cm.
  const std::optional<RayHit> side = IntersectPrimitive(
      cup, Vector3f(1, 0, 0.05f), Vector3f(-1, 0, 0), 0.0f, 10.0f);
  ASSERT_TRUE(side.has_value());
  EXPECT_NEAR(side->t, 1.0f - 0.04f, 1e-5f);
  EXPECT_GT(side->normal.x(), 0.99f);
}

TEST(HollowTest, ARayDownAtAnAngleMeetsTheFarInsideWall) {
  const Primitive cup = Hollow(Shape::kCup, 0.04f, 0.05f, 0.004f);
  // Entering over the near rim at 45 degrees: the far inner wall (36 mm
  // from the axis) faces the ray.
  const Vector3f d = Vector3f(-1, 0, -1).normalized();
  const Vector3f o = Vector3f(0.02f, 0, 0.1f) - d * 0.5f;
  const std::optional<RayHit> hit = IntersectPrimitive(cup, o, d, 0.0f, 10.0f);
  ASSERT_TRUE(hit.has_value());
  const Vector3f p = o + hit->t * d;
  EXPECT_NEAR(std::hypot(p.x(), p.y()), 0.036f, 1e-4f);
  EXPECT_GT(p.z(), 0.004f);
  EXPECT_GT(hit->normal.x(), 0.99f);  // the inner wall faces the axis
}

// Height above the foot of a bowl's inside at `rho` from its axis: the
// sphere through the rim's inner circle (rim_radius at depth below the
// rim) and the floor (depth below the rim), as synth_scene.h describes it.
float InsideHeight(float rim_radius, float depth, float floor, float rho) {
  const float r_in = (rim_radius * rim_radius + depth * depth) / (2 * depth);
  return floor + r_in - std::sqrt(r_in * r_in - rho * rho);
}

TEST(HollowTest, ABowlIsASphericalShellCutFlatWithAFoot) {
  // Radius 8 cm, 5 cm deep, 5 mm wall; the rim is the outer sphere's
  // equator. The inside meets the rim 75 mm out and the floor 5 mm up.
  const Primitive bowl = Hollow(Shape::kBowl, 0.08f, 0.025f, 0.005f);
  // Straight down the axis: the floor, at 5 mm, facing up.
  const std::optional<RayHit> down = IntersectPrimitive(
      bowl, Vector3f(0, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(1.0f - down->t, 0.005f, 1e-5f);
  EXPECT_GT(down->normal.z(), 0.99f);
  // 6 cm off the axis the inside rises smoothly towards the rim; its normal
  // leans towards the axis.
  const std::optional<RayHit> inside = IntersectPrimitive(
      bowl, Vector3f(0.06f, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(1.0f - inside->t, InsideHeight(0.075f, 0.045f, 0.005f, 0.06f),
              1e-4f);
  EXPECT_LT(inside->normal.x(), -0.5f);
  // Just inside the rim's inner circle the inside is at the rim's height.
  const std::optional<RayHit> top = IntersectPrimitive(
      bowl, Vector3f(0.0749f, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(1.0f - top->t, 0.05f, 2e-3f);
  // From below, the flat foot of radius sqrt(0.08^2 - 0.05^2).
  const std::optional<RayHit> foot = IntersectPrimitive(
      bowl, Vector3f(0.05f, 0, -1), Vector3f(0, 0, 1), 0.0f, 10.0f);
  ASSERT_TRUE(foot.has_value());
  EXPECT_NEAR(foot->t, 1.0f, 1e-5f);
  // Beyond the foot (6.5 cm out) a ray from below meets the outer sphere,
  // higher up: z = 0.05 - sqrt(0.08^2 - 0.065^2) = 3.4 mm.
  const std::optional<RayHit> wall = IntersectPrimitive(
      bowl, Vector3f(0.065f, 0, -1), Vector3f(0, 0, 1), 0.0f, 10.0f);
  ASSERT_TRUE(wall.has_value());
  EXPECT_NEAR(wall->t - 1.0f,
              0.05f - std::sqrt(0.08f * 0.08f - 0.065f * 0.065f), 1e-4f);
}

TEST(HollowTest, ABowlOnAFootRingHasItsFloorAtTheFloorHeight) {
  Primitive bowl = Hollow(Shape::kBowl, 0.08f, 0.025f, 0.005f);
  bowl.floor_height = 0.015f;
  // Straight down the axis: the floor 15 mm up, not the wall's 5 mm.
  const std::optional<RayHit> down = IntersectPrimitive(
      bowl, Vector3f(0, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(1.0f - down->t, 0.015f, 1e-5f);
  // 4 cm out, the shallower inside (35 mm deep) as InsideHeight has it.
  const std::optional<RayHit> inside = IntersectPrimitive(
      bowl, Vector3f(0.04f, 0, 1), Vector3f(0, 0, -1), 0.0f, 10.0f);
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(1.0f - inside->t, InsideHeight(0.075f, 0.035f, 0.015f, 0.04f),
              1e-4f);
  SceneSpec spec;
  bowl.floor_height = 0.06f;  // above the 5 cm rim
  spec.objects = {bowl};
  EXPECT_NE(Validate(spec).message().find("floor_height"), std::string::npos);
}

TEST(HollowTest, ValidateRefusesAWallThickerThanTheRadiusAndADeepBowl) {
  SceneSpec spec;
  spec.objects = {Hollow(Shape::kCup, 0.04f, 0.05f, 0.05f)};
  EXPECT_EQ(Validate(spec).code(), absl::StatusCode::kInvalidArgument);
  spec.objects = {Hollow(Shape::kBowl, 0.04f, 0.05f, 0.005f)};  // 10 cm deep
  EXPECT_NE(Validate(spec).message().find("bowl"), std::string::npos);
}

TEST(PileTest, PilesHoldEightToSixteenHouseholdObjectsAllInView) {
  int bowls_or_cups = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScene pile = GeneratePile(seed);
    EXPECT_GE(pile.objects.size(), 8u) << seed;
    EXPECT_LE(pile.objects.size(), 16u) << seed;
    for (const ObjectTruth& o : pile.objects) {
      EXPECT_GT(o.visible_pixels, 0) << seed;
      bowls_or_cups +=
          o.primitive.shape == Shape::kBowl || o.primitive.shape == Shape::kCup;
    }
  }
  EXPECT_GT(bowls_or_cups, 0);
  EXPECT_EQ(GeneratePile(3).frame.name, "pile-3");
}

}  // namespace
}  // namespace fovea::synth
