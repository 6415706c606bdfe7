// One curved body on hand-made point sets whose answer is geometry: a
// bowl's inside and outside lie on one sphere, a mug's inside and side on
// one upright cylinder, a tapered mug's on one upright cone, a thick-walled
// vessel's through its wall; a cup in a bowl or a mug, two cans side by side
// and two planes do not.

#include "core/segmentation/body_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace fovea {
namespace {

constexpr float kPi = static_cast<float>(M_PI);

// 30 x 30 points of `surface`(s, t, noise) over (s, t) in [0, 1]^2, with
// Gaussian noise of `sigma` drawn for each.
template <typename Surface>
std::vector<Eigen::Vector3f> Grid(Surface surface, float sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      points.push_back(surface(i / 29.0f, j / 29.0f, noise(rng)));
    }
  }
  return points;
}

// Points of the sphere of centre c and radius r between polar angles
// [theta0, theta1] (from +z) and azimuths [phi0, phi1], with Gaussian noise
// of `sigma` along the radius.
std::vector<Eigen::Vector3f> SpherePatch(const Eigen::Vector3f& c, float r,
                                         float theta0, float theta1, float phi0,
                                         float phi1, float sigma,
                                         unsigned seed) {
  return Grid(
      [&](float s, float t, float e) {
        const float theta = theta0 + (theta1 - theta0) * s;
        const float phi = phi0 + (phi1 - phi0) * t;
        const Eigen::Vector3f n(std::sin(theta) * std::cos(phi),
                                std::sin(theta) * std::sin(phi),
                                std::cos(theta));
        return Eigen::Vector3f(c + (r + e) * n);
      },
      sigma, seed);
}

// Points of the upright (axis +z) cylinder of axis through c, radius r,
// heights [z0, z1] and azimuths [phi0, phi1], noise along the radius.
std::vector<Eigen::Vector3f> CylinderPatch(const Eigen::Vector3f& c, float r,
                                           float z0, float z1, float phi0,
                                           float phi1, float sigma,
                                           unsigned seed) {
  return Grid(
      [&](float s, float t, float e) {
        const float z = z0 + (z1 - z0) * s;
        const float phi = phi0 + (phi1 - phi0) * t;
        return Eigen::Vector3f(c + Eigen::Vector3f((r + e) * std::cos(phi),
                                                   (r + e) * std::sin(phi), z));
      },
      sigma, seed);
}

// Points of the upright cone of axis through c whose radius is r + taper z
// at height z above c, over heights [z0, z1] and azimuths [phi0, phi1],
// noise along the radius.
std::vector<Eigen::Vector3f> ConePatch(const Eigen::Vector3f& c, float r,
                                       float taper, float z0, float z1,
                                       float phi0, float phi1, float sigma,
                                       unsigned seed) {
  return Grid(
      [&](float s, float t, float e) {
        const float z = z0 + (z1 - z0) * s;
        const float phi = phi0 + (phi1 - phi0) * t;
        const float radius = r + taper * z + e;
        return Eigen::Vector3f(c + Eigen::Vector3f(radius * std::cos(phi),
                                                   radius * std::sin(phi), z));
      },
      sigma, seed);
}

const Eigen::Vector3f kUp = Eigen::Vector3f::UnitZ();
// Bodies 1 m from the camera (z is depth): the Kinect's noise there is
// 1.4 mm, so a fit may miss by hypot(2 mm, 1.4 mm) = 2.5 mm.
const Eigen::Vector3f kAway(0.0f, 0.0f, 1.0f);

TEST(BodyFitTest, FitsRecoverTheRadiusAndCentre) {
  const Eigen::Vector3f c(0.1f, -0.2f, 0.9f);
  const std::optional<BodyFit> sphere =
      FitSphere(SpherePatch(c, 0.08f, 1.8f, 2.8f, 0.0f, 2.0f, 0.0f, 1));
  ASSERT_TRUE(sphere.has_value());
  EXPECT_NEAR(sphere->radius, 0.08f, 1e-4f);
  EXPECT_LT((sphere->center - c).norm(), 1e-4f);
  EXPECT_LT(sphere->rms, 1e-5f);
  const std::optional<BodyFit> cylinder = FitUprightCylinder(
      CylinderPatch(c, 0.04f, 0.0f, 0.1f, 0.0f, 1.5f, 0.0f, 2), kUp);
  ASSERT_TRUE(cylinder.has_value());
  EXPECT_NEAR(cylinder->radius, 0.04f, 1e-4f);
  EXPECT_LT((cylinder->center - c).head<2>().norm(), 1e-4f);
  EXPECT_FALSE(FitSphere({c, c, c}).has_value());  // too few points
}

TEST(BodyFitTest, ABowlsInsideAndOutsideAreOneBody) {
  // A bowl of outer radius 8 cm, walls 4 mm: the outside's front half
  // below the rim and the inside's far half, 1 mm of noise.
  const Eigen::Vector3f c = kAway;
  const std::vector<Eigen::Vector3f> outside =
      SpherePatch(c, 0.08f, 1.7f, 2.6f, 0.5f, 2.6f, 0.001f, 3);
  const std::vector<Eigen::Vector3f> inside =
      SpherePatch(c, 0.076f, 1.7f, 2.6f, 3.6f, 5.8f, 0.001f, 4);
  EXPECT_TRUE(OnOneBody(outside, inside, kUp, BodyFitOptions{}));
  // A cup (radius 4 cm) standing in it is not.
  const std::vector<Eigen::Vector3f> cup =
      CylinderPatch(kAway + Eigen::Vector3f(0.0f, 0.0f, -0.05f), 0.04f, 0.0f,
                    0.06f, 0.5f, 2.6f, 0.001f, 5);
  EXPECT_FALSE(OnOneBody(cup, inside, kUp, BodyFitOptions{}));
}

TEST(BodyFitTest, AMugsInsideAndSideAreOneBodyTwoCansAreNot) {
  const Eigen::Vector3f c = kAway + Eigen::Vector3f(0.3f, 0.1f, 0.0f);
  const std::vector<Eigen::Vector3f> side =
      CylinderPatch(c, 0.04f, 0.0f, 0.1f, 0.3f, 2.8f, 0.001f, 6);
  const std::vector<Eigen::Vector3f> inside =
      CylinderPatch(c, 0.036f, 0.04f, 0.1f, 3.5f, 6.0f, 0.001f, 7);
  EXPECT_TRUE(OnOneBody(side, inside, kUp, BodyFitOptions{}));
  // The same mug on its side (axis along x) is no upright cylinder.
  std::vector<Eigen::Vector3f> lying_side;
  std::vector<Eigen::Vector3f> lying_inside;
  for (const Eigen::Vector3f& p : side) {
    lying_side.emplace_back(p.z() - 1.0f, p.y(), p.x() + 0.7f);
  }
  for (const Eigen::Vector3f& p : inside) {
    lying_inside.emplace_back(p.z() - 1.0f, p.y(), p.x() + 0.7f);
  }
  EXPECT_FALSE(OnOneBody(lying_side, lying_inside, kUp, BodyFitOptions{}));
  // A second can of the same radius 9 cm to the side.
  const std::vector<Eigen::Vector3f> other =
      CylinderPatch(c + Eigen::Vector3f(0.09f, 0.0f, 0.0f), 0.04f, 0.0f, 0.1f,
                    0.3f, 2.8f, 0.001f, 8);
  EXPECT_FALSE(OnOneBody(side, other, kUp, BodyFitOptions{}));
}

TEST(BodyFitTest, ATaperedMugsInsideAndSideAreOneConeTwoCupsAreNot) {
  // A mug 3.5 cm in radius at the bottom, 5 cm at the rim 10 cm up (taper
  // 0.15, 8.5 degrees), walls 3 mm, 1 mm of noise.
  const Eigen::Vector3f c = kAway + Eigen::Vector3f(-0.2f, 0.1f, 0.0f);
  const std::vector<Eigen::Vector3f> side =
      ConePatch(c, 0.035f, 0.15f, 0.0f, 0.1f, 0.3f, 2.8f, 0.001f, 13);
  const std::vector<Eigen::Vector3f> inside =
      ConePatch(c, 0.032f, 0.15f, 0.04f, 0.1f, 3.5f, 6.0f, 0.001f, 14);
  const std::optional<BodyFit> cone = FitUprightCone(side, kUp);
  ASSERT_TRUE(cone.has_value());
  EXPECT_NEAR(cone->taper, 0.15f, 0.01f);
  EXPECT_NEAR(cone->radius, 0.035f + 0.15f * 0.05f, 0.001f);  // mid-height
  EXPECT_LT((cone->center - c).head<2>().norm(), 0.001f);
  EXPECT_TRUE(OnOneBody(side, inside, kUp, BodyFitOptions{}));
  // No cylinder holds both: without cones they are two bodies.
  BodyFitOptions cylinders;
  cylinders.max_taper = 0.0f;
  EXPECT_FALSE(OnOneBody(side, inside, kUp, cylinders));
  // A flower pot flaring at 25 degrees is past max_taper (0.3).
  const std::vector<Eigen::Vector3f> pot_side =
      ConePatch(c, 0.03f, 0.47f, 0.0f, 0.08f, 0.3f, 2.8f, 0.001f, 15);
  const std::vector<Eigen::Vector3f> pot_inside =
      ConePatch(c, 0.027f, 0.47f, 0.03f, 0.08f, 3.5f, 6.0f, 0.001f, 16);
  EXPECT_FALSE(OnOneBody(pot_side, pot_inside, kUp, BodyFitOptions{}));
  BodyFitOptions steep;
  steep.max_taper = 0.5f;
  EXPECT_TRUE(OnOneBody(pot_side, pot_inside, kUp, steep));
  // A second mug of the same shape 11 cm to the side, and the same mug
  // upside down beside it, are not one body with the first.
  EXPECT_FALSE(
      OnOneBody(side,
                ConePatch(c + Eigen::Vector3f(0.11f, 0.0f, 0.0f), 0.035f, 0.15f,
                          0.0f, 0.1f, 0.3f, 2.8f, 0.001f, 17),
                kUp, BodyFitOptions{}));
  EXPECT_FALSE(OnOneBody(side,
                         ConePatch(c + Eigen::Vector3f(0.0f, 0.0f, 0.1f), 0.05f,
                                   -0.15f, 0.0f, 0.1f, 3.5f, 6.0f, 0.001f, 18),
                         kUp, BodyFitOptions{}));
  BodyFitOptions negative;
  negative.max_taper = -0.1f;
  EXPECT_FALSE(Validate(negative).ok());
}

TEST(BodyFitTest, ThickWalledVesselsAreOneBodyThroughTheirWall) {
  // A stoneware bowl and mug, walls 7 mm, seen from above: the inside's
  // far side and flanks, the outside's front and flanks. Where the two
  // overlap in azimuth no one sphere or cylinder fits both within the
  // 2.5 mm the noise and half a thin wall allow; a second radius a wall off
  // the first fits both to the noise.
  const Eigen::Vector3f c = kAway;
  const std::vector<Eigen::Vector3f> bowl_outside =
      SpherePatch(c, 0.08f, 1.7f, 2.6f, 0.5f, 2.6f, 0.001f, 19);
  const std::vector<Eigen::Vector3f> bowl_inside =
      SpherePatch(c, 0.073f, 1.7f, 2.6f, 1.8f, 6.0f, 0.001f, 20);
  const Eigen::Vector3f m = kAway + Eigen::Vector3f(0.3f, 0.1f, 0.0f);
  const std::vector<Eigen::Vector3f> mug_side =
      CylinderPatch(m, 0.04f, 0.0f, 0.1f, 0.3f, 2.8f, 0.001f, 21);
  const std::vector<Eigen::Vector3f> mug_inside =
      CylinderPatch(m, 0.033f, 0.01f, 0.1f, 1.2f, 6.0f, 0.001f, 22);
  BodyFitOptions walls;
  walls.max_wall_m = 0.008f;
  EXPECT_TRUE(OnOneBody(bowl_outside, bowl_inside, kUp, walls));
  EXPECT_TRUE(OnOneBody(mug_side, mug_inside, kUp, walls));
  const BodyFitOptions no_walls;  // the default
  EXPECT_FALSE(OnOneBody(bowl_outside, bowl_inside, kUp, no_walls));
  EXPECT_FALSE(OnOneBody(mug_side, mug_inside, kUp, no_walls));
  // A cup 12 mm narrower than the mug, standing in it, is no wall.
  const std::vector<Eigen::Vector3f> cup_in_mug =
      CylinderPatch(m, 0.028f, 0.01f, 0.1f, 1.2f, 6.0f, 0.001f, 23);
  EXPECT_FALSE(OnOneBody(mug_side, cup_in_mug, kUp, walls));
  BodyFitOptions negative;
  negative.max_wall_m = -0.001f;
  EXPECT_FALSE(Validate(negative).ok());
}

TEST(BodyFitTest, PlanesAndSmallSurfacesAreNotBodies) {
  std::vector<Eigen::Vector3f> top;
  std::vector<Eigen::Vector3f> front;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      top.emplace_back(0.003f * i, 0.003f * j, 1.1f);
      front.emplace_back(0.003f * i, 0.0f, 1.1f - 0.003f * j);
    }
  }
  EXPECT_FALSE(OnOneBody(top, front, kUp, BodyFitOptions{}));
  // Fewer points than min_points: no decision.
  const Eigen::Vector3f c = kAway;
  std::vector<Eigen::Vector3f> a =
      SpherePatch(c, 0.08f, 1.7f, 2.6f, 0.5f, 2.6f, 0.0f, 9);
  std::vector<Eigen::Vector3f> b =
      SpherePatch(c, 0.08f, 1.7f, 2.6f, 3.6f, 5.8f, 0.0f, 10);
  BodyFitOptions options;
  options.min_points = 1000;
  EXPECT_FALSE(OnOneBody(a, b, kUp, options));
  options.min_points = 2;
  EXPECT_FALSE(Validate(options).ok());
  // Farther, the noise allows more: 1 mm off a sphere is too much with no
  // wall and no noise, not at 2 m with the Kinect's.
  a = SpherePatch(c, 0.08f, 1.7f, 2.6f, 0.5f, 2.6f, 0.003f, 11);
  b = SpherePatch(c, 0.08f, 1.7f, 2.6f, 3.6f, 5.8f, 0.003f, 12);
  EXPECT_FALSE(OnOneBody(a, b, kUp, BodyFitOptions{}));
  for (Eigen::Vector3f& p : a) p.z() += 1.0f;
  for (Eigen::Vector3f& p : b) p.z() += 1.0f;
  EXPECT_TRUE(OnOneBody(a, b, kUp, BodyFitOptions{}));
}

}  // namespace
}  // namespace fovea
