#include "core/synth/random_bodies.h"

#include <algorithm>
#include <cmath>

namespace fovea::synth {
namespace {

using Eigen::Vector3f;

// Object sizes in metres: household objects 3-15 cm across.
constexpr float kBoxHalfMax = 0.07f;
constexpr float kBoxHalfHeightMax = 0.06f;
constexpr float kCylinderRadiusMin = 0.018f;
constexpr float kCylinderRadiusMax = 0.045f;
constexpr float kCylinderHalfHeightMax = 0.075f;
constexpr float kSphereRadiusMin = 0.025f;
constexpr float kSphereRadiusMax = 0.055f;
constexpr float kConeRadiusMin = 0.025f;
constexpr float kConeRadiusMax = 0.055f;
constexpr float kConeHalfHeightMin = 0.035f;
constexpr float kConeHalfHeightMax = 0.07f;

// Shape mix (box, cylinder, sphere, cone) and cylinder poses.
constexpr float kShapeWeights[4] = {0.35f, 0.3f, 0.15f, 0.2f};
constexpr float kLyingCylinderProbability = 0.3f;

// Object colours: HSV ranges; dark objects have value below kDarkValueMax.
constexpr float kSaturationMin = 0.35f;
constexpr float kSaturationMax = 0.9f;
constexpr float kValueMin = 0.45f;
constexpr float kValueMax = 0.95f;
constexpr float kDarkValueMin = 0.03f;
constexpr float kDarkValueMax = 0.09f;
constexpr float kMinColorDistanceToTable = 0.25f;  // RGB, [0, 1] units
// Non-dark objects stay well above NoiseOptions::dark_albedo (0.12), so that
// only dark_object_probability makes objects lose depth.
constexpr float kMinLuminance = 0.2f;

Shape RandomShape(Random& rng) {
  float r = static_cast<float>(rng.Uniform());
  for (int i = 0; i < 3; ++i) {
    if (r < kShapeWeights[i]) return static_cast<Shape>(i);
    r -= kShapeWeights[i];
  }
  return Shape::kCone;
}

// The household mix: what a kitchen or office table holds.
enum class HouseholdKind {
  kBox,
  kBook,
  kCylinder,
  kBowl,
  kCup,
  kSphere,
  kCone
};
constexpr float kHouseholdWeights[7] = {0.25f, 0.12f, 0.2f, 0.13f,
                                        0.15f, 0.05f, 0.1f};

// The size of a box, cylinder, sphere or cone (body.shape; any other
// shape is drawn as a cone), as both mixes draw them.
void DrawBasicSize(Body& body, Random& rng) {
  switch (body.shape) {
    case Shape::kBox:
      body.half_extents = {rng.Uniform(kBoxHalfMin, kBoxHalfMax),
                           rng.Uniform(kBoxHalfMin, kBoxHalfMax),
                           rng.Uniform(kBoxHalfMin, kBoxHalfHeightMax)};
      break;
    case Shape::kCylinder:
      body.radius = rng.Uniform(kCylinderRadiusMin, kCylinderRadiusMax);
      body.half_extents = {
          body.radius, body.radius,
          rng.Uniform(kCylinderHalfHeightMin, kCylinderHalfHeightMax)};
      body.lying = rng.Bernoulli(kLyingCylinderProbability);
      break;
    case Shape::kSphere:
      body.radius = rng.Uniform(kSphereRadiusMin, kSphereRadiusMax);
      body.half_extents = Vector3f::Constant(body.radius);
      break;
    default:
      body.shape = Shape::kCone;
      body.radius = rng.Uniform(kConeRadiusMin, kConeRadiusMax);
      body.half_extents = {body.radius, body.radius,
                           rng.Uniform(kConeHalfHeightMin, kConeHalfHeightMax)};
      break;
  }
}

}  // namespace

Vector3f HsvToRgb(float h, float s, float v) {
  const float c = v * s;
  const float hp = h * 6.0f;
  const float x = c * (1.0f - std::abs(std::fmod(hp, 2.0f) - 1.0f));
  Vector3f rgb;
  switch (static_cast<int>(hp) % 6) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  return rgb + Vector3f::Constant(v - c);
}

Vector3f RandomAlbedo(const Vector3f& table_rgb, float dark_probability,
                      Random& rng) {
  if (rng.Bernoulli(dark_probability)) {
    return HsvToRgb(static_cast<float>(rng.Uniform()), rng.Uniform(0.0f, 0.5f),
                    rng.Uniform(kDarkValueMin, kDarkValueMax));
  }
  Vector3f rgb;
  do {
    rgb = HsvToRgb(static_cast<float>(rng.Uniform()),
                   rng.Uniform(kSaturationMin, kSaturationMax),
                   rng.Uniform(kValueMin, kValueMax));
  } while ((rgb - table_rgb).norm() < kMinColorDistanceToTable ||
           rgb.dot(Vector3f(0.299f, 0.587f, 0.114f)) < kMinLuminance);
  return rgb;
}

// Household bodies, metres: books lie flat; bowls are 10-18 cm across and
// 45-70 % as deep as their radius; cups 6-9 cm across, 8-12 cm tall.
Body RandomHouseholdBody(const Vector3f& rgb, Random& rng) {
  float r = static_cast<float>(rng.Uniform());
  int kind = 0;
  for (; kind < 6 && r >= kHouseholdWeights[kind]; ++kind) {
    r -= kHouseholdWeights[kind];
  }
  Body body;
  body.rgb = rgb;
  switch (static_cast<HouseholdKind>(kind)) {
    case HouseholdKind::kBook:
      body.shape = Shape::kBox;
      body.half_extents = {rng.Uniform(0.06f, 0.11f), rng.Uniform(0.04f, 0.08f),
                           rng.Uniform(0.008f, 0.02f)};
      return body;
    case HouseholdKind::kBowl:
      body.shape = Shape::kBowl;
      // A cereal or salad bowl: 4-9 cm deep, its floor on a foot ring.
      body.radius = rng.Uniform(0.05f, 0.09f);
      body.half_extents = {body.radius, body.radius,
                           body.radius * rng.Uniform(0.6f, 0.9f) / 2.0f};
      body.thickness = rng.Uniform(0.004f, 0.008f);
      body.floor_height = rng.Uniform(0.01f, 0.018f);
      return body;
    case HouseholdKind::kCup:
      body.shape = Shape::kCup;
      body.radius = rng.Uniform(0.03f, 0.045f);
      body.half_extents = {body.radius, body.radius, rng.Uniform(0.04f, 0.06f)};
      body.thickness = rng.Uniform(0.003f, 0.005f);
      return body;
    default:
      break;
  }
  // Boxes, cylinders, spheres and cones as RandomBody draws them.
  static constexpr Shape kRest[] = {Shape::kBox, Shape::kBox, Shape::kCylinder,
                                    Shape::kBox, Shape::kBox, Shape::kSphere,
                                    Shape::kCone};
  body.shape = kRest[kind];
  DrawBasicSize(body, rng);
  return body;
}

Body RandomBody(const Vector3f& rgb, Random& rng) {
  Body body;
  body.shape = RandomShape(rng);
  body.rgb = rgb;
  DrawBasicSize(body, rng);
  return body;
}

}  // namespace fovea::synth
