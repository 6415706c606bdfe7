#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/stacked_bodies.h"
#include "core/synth/stacked_bodies_internal.h"
#include "core/synth/synth_scene.h"

// The bodies real frames showed cut or missed (StackedPileOptions::
// more_kinds): a drill, a banana, a pen, small flat parts.

namespace fovea::synth::pile_internal {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

constexpr float kToolBodies[][3] = {{0.10f, 0.55f, 0.60f},
                                    {0.90f, 0.70f, 0.10f},
                                    {0.80f, 0.20f, 0.12f},
                                    {0.25f, 0.50f, 0.25f}};
constexpr float kMetal[3] = {0.55f, 0.56f, 0.58f};
constexpr float kBanana[3] = {0.92f, 0.80f, 0.22f};
constexpr float kPlastics[][3] = {{0.85f, 0.15f, 0.15f}, {0.15f, 0.35f, 0.80f},
                                  {0.95f, 0.75f, 0.10f}, {0.20f, 0.65f, 0.30f},
                                  {0.92f, 0.92f, 0.90f}, {0.60f, 0.30f, 0.70f}};

// A cylinder of radius r and half length hl lying along the horizontal
// direction `yaw` (radians), its axis at height r above z = 0, centred at
// `xy`.
Primitive LyingCylinder(const Vector2f& xy, float yaw, float r, float hl,
                        const Vector3f& rgb) {
  Primitive p;
  p.shape = Shape::kCylinder;
  p.radius = r;
  p.half_extents = Vector3f(r, r, hl);
  p.pose.linear() = (Eigen::AngleAxisf(yaw, Vector3f::UnitZ()) *
                     Eigen::AngleAxisf(kPi / 2.0f, Vector3f::UnitY()))
                        .toRotationMatrix();
  p.pose.translation() = Vector3f(xy.x(), xy.y(), r);
  p.rgb = rgb;
  return p;
}

// The footprint of LyingCylinder's cylinder.
Footprint LyingFootprint(const Vector2f& xy, float yaw, float r, float hl) {
  Footprint f = Rect(xy, Vector2f(hl, r), 0.0f, 2.0f * r);
  f.yaw = yaw;
  return f;
}

// The hull of `solids`: the rectangle (axis-aligned) around them.
Footprint HullOf(const std::vector<Footprint>& solids) {
  Vector2f lo = Vector2f::Constant(std::numeric_limits<float>::infinity());
  Vector2f hi = -lo;
  float z_max = 0.0f;
  for (const Footprint& f : solids) {
    const Vector2f half(f.ProjectedRadius(Vector2f::UnitX()),
                        f.ProjectedRadius(Vector2f::UnitY()));
    lo = lo.cwiseMin(f.centre - half);
    hi = hi.cwiseMax(f.centre + half);
    z_max = std::max(z_max, f.z_max);
  }
  return Rect((lo + hi) / 2.0f, (hi - lo) / 2.0f, 0.0f, z_max);
}

}  // namespace

// A cordless drill standing on its battery: battery block, handle, barrel
// across the top (forward along +x) and chuck, in three colours.
std::optional<PileBody> MakeDrill(float room, const Vector3f& table_rgb,
                                  Random& rng) {
  const float barrel_hl = rng.Uniform(0.07f, 0.09f);
  if (room < 0.06f) return std::nullopt;
  const Vector3f body_rgb = Pick(kToolBodies, table_rgb, rng);
  const Vector3f battery(rng.Uniform(0.035f, 0.045f),
                         rng.Uniform(0.03f, 0.038f),
                         rng.Uniform(0.012f, 0.018f));
  const Vector3f handle(0.016f, 0.02f, rng.Uniform(0.045f, 0.06f));
  const float barrel_r = rng.Uniform(0.026f, 0.032f);
  const float handle_top = 2.0f * battery.z() + 2.0f * handle.z();
  const float barrel_z = handle_top + barrel_r * 0.6f;
  const float barrel_x = barrel_hl * 0.45f;  // the barrel reaches forward
  const float chuck_r = rng.Uniform(0.011f, 0.015f);
  const float chuck_hl = rng.Uniform(0.015f, 0.02f);
  PileBody body;
  // The battery first: the object's primitive, standing on z = 0.
  body.primitives.push_back(
      BoxPrimitive(Vector3f(0, 0, battery.z()), battery, Rgb(kSlate)));
  body.primitives.push_back(BoxPrimitive(
      Vector3f(0, 0, 2.0f * battery.z() + handle.z()), handle, body_rgb));
  Primitive barrel;
  barrel.shape = Shape::kCylinder;
  barrel.radius = barrel_r;
  barrel.half_extents = Vector3f(barrel_r, barrel_r, barrel_hl);
  barrel.pose.linear() =
      Eigen::AngleAxisf(kPi / 2.0f, Vector3f::UnitY()).toRotationMatrix();
  barrel.pose.translation() = Vector3f(barrel_x, 0, barrel_z);
  barrel.rgb = body_rgb;
  body.primitives.push_back(barrel);
  Primitive chuck = barrel;
  chuck.radius = chuck_r;
  chuck.half_extents = Vector3f(chuck_r, chuck_r, chuck_hl);
  chuck.pose.translation() =
      Vector3f(barrel_x + barrel_hl + chuck_hl, 0, barrel_z);
  chuck.rgb = Rgb(kMetal);
  body.primitives.push_back(chuck);
  const float top = barrel_z + barrel_r;
  body.solids = {
      Rect(Vector2f::Zero(), battery.head<2>(), 0.0f, 2.0f * battery.z()),
      Rect(Vector2f::Zero(), handle.head<2>(), 0.0f, handle_top),
      Rect(Vector2f(barrel_x, 0), Vector2f(barrel_hl, barrel_r),
           barrel_z - barrel_r, top),
      Rect(Vector2f(barrel_x + barrel_hl + chuck_hl, 0),
           Vector2f(chuck_hl, chuck_r), barrel_z - chuck_r,
           barrel_z + chuck_r)};
  body.hull = HullOf(body.solids);
  body.hull.z_min = 0.0f;
  if (std::min(body.hull.half.x(), body.hull.half.y()) > room) {
    return std::nullopt;
  }
  return body;
}

// A banana lying flat: four segments along an arc (turning 18-25 degrees
// each), the end ones thinner, with a ball at each inner joint.
std::optional<PileBody> MakeBanana(float room, Random& rng) {
  const float r = rng.Uniform(0.016f, 0.02f);
  const float seg_hl = rng.Uniform(0.02f, 0.025f);
  const float turn = rng.Uniform(0.31f, 0.44f);
  if (room < 2.0f * r) return std::nullopt;
  const Vector3f rgb = Rgb(kBanana) * rng.Uniform(0.92f, 1.03f);
  PileBody body;
  Vector2f at(-3.0f * seg_hl, 0.0f);
  float yaw = -1.5f * turn;
  for (int k = 0; k < 4; ++k) {
    const float rk = (k == 0 || k == 3) ? r * 0.8f : r;
    const Vector2f dir(std::cos(yaw), std::sin(yaw));
    const Vector2f centre = at + seg_hl * dir;
    Primitive segment =
        LyingCylinder(centre, yaw, rk, seg_hl, rgb.cwiseMin(1.0f));
    // Thinner segments lie on the table too.
    body.primitives.push_back(segment);
    body.solids.push_back(LyingFootprint(centre, yaw, rk, seg_hl));
    at = centre + seg_hl * dir;
    if (k < 3) {
      Primitive joint;
      joint.shape = Shape::kSphere;
      joint.radius = r * 0.95f;
      joint.half_extents = Vector3f::Constant(joint.radius);
      joint.pose.translation() = Vector3f(at.x(), at.y(), joint.radius);
      joint.rgb = segment.rgb;
      body.primitives.push_back(joint);
    }
    yaw += turn;
  }
  body.hull = HullOf(body.solids);
  if (std::min(body.hull.half.x(), body.hull.half.y()) > room) {
    return std::nullopt;
  }
  return body;
}

// A pen lying flat, its cap (a little wider, another colour) on one end.
std::optional<PileBody> MakePen(float room, const Vector3f& table_rgb,
                                Random& rng) {
  const float r = rng.Uniform(0.0055f, 0.0075f);
  const float hl = rng.Uniform(0.06f, 0.075f);
  if (room < r) return std::nullopt;
  PileBody body;
  body.primitives.push_back(LyingCylinder(Vector2f::Zero(), 0.0f, r, hl,
                                          Pick(kPlastics, table_rgb, rng)));
  const float cap_hl = 0.0125f;
  const float cap_r = r + 0.0006f;
  body.primitives.push_back(LyingCylinder(Vector2f(hl - cap_hl, 0), 0.0f, cap_r,
                                          cap_hl,
                                          Pick(kPlastics, table_rgb, rng)));
  body.solids = {LyingFootprint(Vector2f::Zero(), 0.0f, cap_r, hl)};
  body.hull = body.solids[0];
  return body;
}

// A small flat part: a plastic block or disc.
std::optional<PileBody> MakePart(float room, const Vector3f& table_rgb,
                                 Random& rng) {
  const Vector3f rgb = Pick(kPlastics, table_rgb, rng);
  const float hz = rng.Uniform(0.005f, 0.0075f);
  PileBody body;
  if (rng.Bernoulli(0.5)) {
    const std::optional<float> hx = Capped(0.0125f, 0.025f, room, rng);
    if (!hx) return std::nullopt;
    const Vector3f half(*hx, *hx * rng.Uniform(0.6f, 1.0f), hz);
    body.primitives.push_back(BoxPrimitive(Vector3f(0, 0, hz), half, rgb));
    SetBoxVolumes(half, body);
    body.top.reset();
  } else {
    const std::optional<float> r = Capped(0.0125f, 0.025f, room, rng);
    if (!r) return std::nullopt;
    Primitive p;
    p.shape = Shape::kCylinder;
    p.radius = *r;
    p.half_extents = Vector3f(*r, *r, hz);
    p.pose.translation() = Vector3f(0, 0, hz);
    p.rgb = rgb;
    body.primitives.push_back(p);
    body.hull = Disc(*r, 0.0f, 2.0f * hz);
    body.solids = {body.hull};
  }
  return body;
}
}  // namespace fovea::synth::pile_internal
