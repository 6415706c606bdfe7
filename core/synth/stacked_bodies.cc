#include "core/synth/stacked_bodies.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <string_view>
#include <vector>

#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

constexpr float kPi = 3.14159265358979f;

// Household palettes, RGB albedo in [0, 1]. All keep a luminance above
// 0.18, so that no sensor drops their depth as too dark
// (NoiseOptions::dark_albedo is 0.12-0.15).
constexpr float kBookCovers[][3] = {
    {0.55f, 0.12f, 0.10f}, {0.14f, 0.22f, 0.45f}, {0.16f, 0.38f, 0.22f},
    {0.86f, 0.80f, 0.64f}, {0.90f, 0.90f, 0.87f}, {0.85f, 0.45f, 0.12f},
    {0.12f, 0.46f, 0.52f}, {0.45f, 0.20f, 0.42f}, {0.80f, 0.70f, 0.15f}};
constexpr float kPages[3] = {0.93f, 0.91f, 0.84f};
constexpr float kCardboard[3] = {0.74f, 0.58f, 0.40f};
constexpr float kPrintedBoxes[][3] = {
    {0.80f, 0.10f, 0.08f}, {0.95f, 0.80f, 0.15f}, {0.15f, 0.35f, 0.75f},
    {0.20f, 0.60f, 0.30f}, {0.92f, 0.92f, 0.90f}, {0.90f, 0.50f, 0.60f}};
constexpr float kCeramics[][3] = {{0.93f, 0.93f, 0.91f}, {0.88f, 0.84f, 0.72f},
                                  {0.30f, 0.65f, 0.62f}, {0.20f, 0.35f, 0.65f},
                                  {0.75f, 0.18f, 0.15f}, {0.95f, 0.78f, 0.20f},
                                  {0.35f, 0.55f, 0.30f}, {0.25f, 0.25f, 0.28f}};
constexpr float kCans[][3] = {{0.75f, 0.12f, 0.10f}, {0.72f, 0.72f, 0.74f},
                              {0.20f, 0.50f, 0.25f}, {0.90f, 0.75f, 0.20f},
                              {0.45f, 0.25f, 0.12f}, {0.55f, 0.75f, 0.85f}};
constexpr float kBins[][3] = {{0.20f, 0.35f, 0.70f},
                              {0.60f, 0.61f, 0.63f},
                              {0.90f, 0.90f, 0.88f},
                              {0.85f, 0.30f, 0.20f}};
constexpr float kCrate[3] = {0.86f, 0.72f, 0.50f};
constexpr float kToolBodies[][3] = {{0.10f, 0.55f, 0.60f},
                                    {0.90f, 0.70f, 0.10f},
                                    {0.80f, 0.20f, 0.12f},
                                    {0.25f, 0.50f, 0.25f}};
constexpr float kMetal[3] = {0.55f, 0.56f, 0.58f};
constexpr float kBanana[3] = {0.92f, 0.80f, 0.22f};
constexpr float kPlastics[][3] = {{0.85f, 0.15f, 0.15f}, {0.15f, 0.35f, 0.80f},
                                  {0.95f, 0.75f, 0.10f}, {0.20f, 0.65f, 0.30f},
                                  {0.92f, 0.92f, 0.90f}, {0.60f, 0.30f, 0.70f}};
constexpr float kSlate[3] = {0.24f, 0.25f, 0.28f};
// Colours are jittered by this much per channel and kept this far (RGB
// distance) from the table.
constexpr float kColourJitter = 0.04f;
constexpr float kMinDistanceToTable = 0.15f;
constexpr int kColourAttempts = 8;

// Book: the pages show 0.5 mm proud of the cover on three sides, in strips
// this thick, between covers this thick.
constexpr float kPagesProud = 0.0005f;
constexpr float kPagesStrip = 0.003f;
// Mug handle: bar and arm thickness, half width across.
constexpr float kHandleBar = 0.008f;
constexpr float kHandleArm = 0.01f;
constexpr float kHandleHalfWidth = 0.006f;
constexpr float kHandleIntoWall = 0.003f;  // arms reach into the cup wall
// Open box: contents keep this far from the walls; bowls' contents stay
// this far inside the flat floor.
constexpr float kInnerGap = 0.003f;

template <size_t N>
Vector3f Pick(const float (&palette)[N][3], const Vector3f& table_rgb,
              Random& rng) {
  Vector3f rgb;
  for (int attempt = 0; attempt < kColourAttempts; ++attempt) {
    const float* c = palette[rng.UniformInt(0, static_cast<int>(N) - 1)];
    rgb = Vector3f(c[0], c[1], c[2]) +
          Vector3f(rng.Uniform(-kColourJitter, kColourJitter),
                   rng.Uniform(-kColourJitter, kColourJitter),
                   rng.Uniform(-kColourJitter, kColourJitter));
    rgb = rgb.cwiseMax(0.0f).cwiseMin(1.0f);
    if ((rgb - table_rgb).norm() >= kMinDistanceToTable) break;
  }
  return rgb;
}

Vector3f Rgb(const float (&c)[3]) { return {c[0], c[1], c[2]}; }

Footprint Rect(const Vector2f& centre, const Vector2f& half, float z_min,
               float z_max) {
  Footprint f;
  f.is_circle = false;
  f.centre = centre;
  f.half = half;
  f.z_min = z_min;
  f.z_max = z_max;
  return f;
}

Footprint Disc(float radius, float z_min, float z_max) {
  Footprint f;
  f.radius = radius;
  f.z_min = z_min;
  f.z_max = z_max;
  return f;
}

// Uniform in [lo, min(hi, cap)], or nullopt when cap < lo.
std::optional<float> Capped(float lo, float hi, float cap, Random& rng) {
  if (cap < lo) return std::nullopt;
  return rng.Uniform(lo, std::min(hi, cap));
}

// A box-shaped body (book, box, tablet): its solid, hull and top.
void SetBoxVolumes(const Vector3f& half, PileBody& body) {
  const float height = 2.0f * half.z();
  body.hull = Rect(Vector2f::Zero(), half.head<2>(), 0.0f, height);
  body.solids = {body.hull};
  body.top = Rect(Vector2f::Zero(), half.head<2>(), height, height);
}

std::optional<PileBody> MakeBook(float room, const Vector3f& table_rgb,
                                 Random& rng) {
  const std::optional<float> hx = Capped(0.075f, 0.125f, room, rng);
  if (!hx) return std::nullopt;
  const Vector3f half(*hx, *hx * rng.Uniform(0.65f, 0.8f),
                      rng.Uniform(0.01f, 0.025f));
  const Vector3f cover = Pick(kBookCovers, table_rgb, rng);
  const float board = rng.Uniform(0.0015f, 0.003f);
  PileBody body;
  body.primitives.push_back(
      BoxPrimitive(Vector3f(0, 0, half.z()), half, cover, Texture::kPaint));
  // Pages on the +x, +y and -y sides (the spine is at -x), between the
  // covers, a hair proud of the cover box.
  const Vector3f pages = Rgb(kPages) * rng.Uniform(0.92f, 1.0f);
  const float page_half_z = half.z() - board;
  const float sx = half.x() + kPagesProud - kPagesStrip / 2;
  const float sy = half.y() + kPagesProud - kPagesStrip / 2;
  const float spine = 2.0f * board;
  body.primitives.push_back(BoxPrimitive(
      Vector3f(sx, 0, half.z()),
      Vector3f(kPagesStrip / 2, half.y() + kPagesProud, page_half_z), pages));
  for (const float s : {-1.0f, 1.0f}) {
    body.primitives.push_back(
        BoxPrimitive(Vector3f(spine / 2 + kPagesProud / 2, s * sy, half.z()),
                     Vector3f(half.x() - spine / 2 + kPagesProud / 2,
                              kPagesStrip / 2, page_half_z),
                     pages));
  }
  const Vector3f outer(half.x() + kPagesProud, half.y() + kPagesProud,
                       half.z());
  SetBoxVolumes(outer, body);
  body.top =
      Rect(Vector2f::Zero(), half.head<2>(), 2.0f * half.z(), 2.0f * half.z());
  return body;
}

std::optional<PileBody> MakeBox(float room, bool stacked,
                                const Vector3f& table_rgb, Random& rng) {
  const std::optional<float> hx = Capped(0.025f, 0.07f, room, rng);
  const std::optional<float> hy = Capped(0.025f, 0.07f, room, rng);
  if (!hx || !hy) return std::nullopt;
  const Vector3f half(*hx, *hy, rng.Uniform(0.02f, stacked ? 0.045f : 0.06f));
  const bool cardboard = rng.Bernoulli(0.4);
  PileBody body;
  body.primitives.push_back(
      BoxPrimitive(Vector3f(0, 0, half.z()), half,
                   cardboard ? Rgb(kCardboard) * rng.Uniform(0.9f, 1.05f)
                             : Pick(kPrintedBoxes, table_rgb, rng),
                   cardboard ? Texture::kPaint : Texture::kFlat));
  SetBoxVolumes(half, body);
  return body;
}

std::optional<PileBody> MakeTablet(float room, Random& rng) {
  const std::optional<float> hx = Capped(0.1f, 0.125f, room, rng);
  if (!hx) return std::nullopt;
  const Vector3f half(*hx, *hx * rng.Uniform(0.65f, 0.72f),
                      rng.Uniform(0.005f, 0.008f));
  PileBody body;
  body.primitives.push_back(
      BoxPrimitive(Vector3f(0, 0, half.z()), half, Rgb(kSlate)));
  SetBoxVolumes(half, body);
  return body;
}

std::optional<PileBody> MakePlate(float room, const Vector3f& table_rgb,
                                  Random& rng) {
  const std::optional<float> r = Capped(0.09f, 0.12f, room, rng);
  if (!r) return std::nullopt;
  const float hz = rng.Uniform(0.005f, 0.009f);
  Primitive p;
  p.shape = Shape::kCylinder;
  p.radius = *r;
  p.half_extents = Vector3f(*r, *r, hz);
  p.pose.translation() = Vector3f(0, 0, hz);
  p.rgb = Pick(kCeramics, table_rgb, rng);
  PileBody body;
  body.primitives.push_back(p);
  body.hull = Disc(*r, 0.0f, 2.0f * hz);
  body.solids = {body.hull};
  body.top = Disc(0.85f * *r, 2.0f * hz, 2.0f * hz);
  return body;
}

Primitive Cup(float r, float hz, float wall, const Vector3f& rgb) {
  Primitive p;
  p.shape = Shape::kCup;
  p.radius = r;
  p.half_extents = Vector3f(r, r, hz);
  p.thickness = wall;
  p.pose.translation() = Vector3f(0, 0, hz);
  p.rgb = rgb;
  return p;
}

std::optional<PileBody> MakeCup(float room, const Vector3f& table_rgb,
                                Random& rng) {
  const std::optional<float> r = Capped(0.026f, 0.04f, room, rng);
  if (!r) return std::nullopt;
  const float hz = rng.Uniform(0.04f, 0.055f);
  PileBody body;
  body.primitives.push_back(Cup(*r, hz, rng.Uniform(0.003f, 0.004f),
                                Pick(kCeramics, table_rgb, rng)));
  body.hull = Disc(*r, 0.0f, 2.0f * hz);
  body.solids = {body.hull};
  return body;
}

// A cup with a handle towards +x: two arms from the wall and a bar joining
// their ends, a "C" on its side.
std::optional<PileBody> MakeMug(float room, const Vector3f& table_rgb,
                                Random& rng) {
  const float reach = rng.Uniform(0.018f, 0.026f);
  const std::optional<float> r = Capped(0.034f, 0.045f, room - reach, rng);
  if (!r) return std::nullopt;
  const float hz = rng.Uniform(0.04f, 0.05f);
  const Vector3f rgb = Pick(kCeramics, table_rgb, rng);
  PileBody body;
  body.primitives.push_back(Cup(*r, hz, 0.004f, rgb));
  const float z_low = 2.0f * hz * 0.25f;
  const float z_high = 2.0f * hz * 0.8f;
  const float arm_x0 = *r - kHandleIntoWall;
  const float arm_x1 = *r + reach - kHandleBar;
  for (const float z : {z_low, z_high}) {
    body.primitives.push_back(BoxPrimitive(
        Vector3f((arm_x0 + arm_x1) / 2, 0, z),
        Vector3f((arm_x1 - arm_x0) / 2, kHandleHalfWidth, kHandleArm / 2),
        rgb));
  }
  const float bar_z0 = z_low - kHandleArm / 2;
  const float bar_z1 = z_high + kHandleArm / 2;
  body.primitives.push_back(BoxPrimitive(
      Vector3f(*r + reach - kHandleBar / 2, 0, (bar_z0 + bar_z1) / 2),
      Vector3f(kHandleBar / 2, kHandleHalfWidth, (bar_z1 - bar_z0) / 2), rgb));
  body.hull = Disc(*r + reach, 0.0f, 2.0f * hz);
  body.solids = {Disc(*r, 0.0f, 2.0f * hz),
                 Rect(Vector2f(*r + reach / 2, 0),
                      Vector2f(reach / 2, kHandleHalfWidth), bar_z0, bar_z1)};
  return body;
}

// A bowl with a flat inner floor wide enough for a cup.
std::optional<PileBody> MakeBowl(float room, const Vector3f& table_rgb,
                                 Random& rng) {
  const std::optional<float> r = Capped(0.065f, 0.09f, room, rng);
  if (!r) return std::nullopt;
  Primitive p;
  p.shape = Shape::kBowl;
  p.radius = *r;
  const float hz = *r * rng.Uniform(0.3f, 0.38f);
  p.half_extents = Vector3f(*r, *r, hz);
  p.thickness = rng.Uniform(0.004f, 0.006f);
  p.floor_height = rng.Uniform(0.008f, 0.014f);
  // The flat floor's limits (synth_scene.h): the inside widens upwards,
  // and the floor lies over the foot.
  const float rim = *r - p.thickness;
  const float depth = 2.0f * hz - p.floor_height;
  const float foot = std::sqrt(*r * *r - 4.0f * hz * hz);
  p.floor_radius =
      std::min({*r * rng.Uniform(0.5f, 0.6f),
                std::sqrt(rim * rim - depth * depth) - 0.001f, foot - 0.004f});
  p.pose.translation() = Vector3f(0, 0, hz);
  p.rgb = Pick(kCeramics, table_rgb, rng);
  PileBody body;
  body.primitives.push_back(p);
  body.hull = Disc(*r, 0.0f, 2.0f * hz);
  body.solids = {body.hull};
  body.top = Disc(p.floor_radius - kInnerGap, p.floor_height, p.floor_height);
  body.cavity = true;
  return body;
}

// An open-top box: a bottom between four walls standing on the table.
PileBody MakeOpenBox(const Vector3f& table_rgb, Random& rng) {
  const Vector2f half(rng.Uniform(0.1f, 0.175f), rng.Uniform(0.1f, 0.16f));
  const float height = rng.Uniform(0.08f, 0.15f);
  const float wall = rng.Uniform(0.005f, 0.008f);
  const float bottom = rng.Uniform(0.005f, 0.01f);
  const int look = rng.UniformInt(0, 2);  // cardboard, plastic, crate
  const Vector3f rgb = look == 0   ? Rgb(kCardboard) * rng.Uniform(0.9f, 1.05f)
                       : look == 1 ? Pick(kBins, table_rgb, rng)
                                   : Rgb(kCrate) * rng.Uniform(0.9f, 1.0f);
  const Texture texture = look == 0   ? Texture::kPaint
                          : look == 1 ? Texture::kFlat
                                      : Texture::kWood;
  const Vector2f inner = half - Vector2f::Constant(wall);
  PileBody body;
  body.primitives.push_back(
      BoxPrimitive(Vector3f(0, 0, bottom / 2),
                   Vector3f(inner.x(), inner.y(), bottom / 2), rgb, texture));
  body.solids.push_back(Rect(Vector2f::Zero(), inner, 0.0f, bottom));
  for (const float s : {-1.0f, 1.0f}) {  // front and back, full length
    const Vector2f c(0, s * (half.y() - wall / 2));
    const Vector2f h(half.x(), wall / 2);
    body.primitives.push_back(BoxPrimitive(Vector3f(c.x(), c.y(), height / 2),
                                           Vector3f(h.x(), h.y(), height / 2),
                                           rgb, texture));
    body.solids.push_back(Rect(c, h, 0.0f, height));
  }
  for (const float s : {-1.0f, 1.0f}) {  // the sides, between them
    const Vector2f c(s * (half.x() - wall / 2), 0);
    const Vector2f h(wall / 2, inner.y());
    body.primitives.push_back(BoxPrimitive(Vector3f(c.x(), c.y(), height / 2),
                                           Vector3f(h.x(), h.y(), height / 2),
                                           rgb, texture));
    body.solids.push_back(Rect(c, h, 0.0f, height));
  }
  body.hull = Rect(Vector2f::Zero(), half, 0.0f, height);
  body.top = Rect(Vector2f::Zero(), inner - Vector2f::Constant(kInnerGap),
                  bottom, bottom);
  return body;
}

// A can or bottle: lying along +x (3 in 4) or standing.
std::optional<PileBody> MakeCan(float room, const Vector3f& table_rgb,
                                Random& rng) {
  const bool lying = rng.Bernoulli(0.75);
  const bool bottle = rng.Bernoulli(0.35);
  const float r =
      bottle ? rng.Uniform(0.028f, 0.035f) : rng.Uniform(0.028f, 0.04f);
  const std::optional<float> hz =
      bottle ? Capped(0.08f, 0.11f, lying ? room : 0.11f, rng)
             : Capped(0.05f, 0.065f, lying ? room : 0.065f, rng);
  if (!hz || (!lying && r > room)) return std::nullopt;
  Primitive p;
  p.shape = Shape::kCylinder;
  p.radius = r;
  p.half_extents = Vector3f(r, r, *hz);
  p.rgb = Pick(kCans, table_rgb, rng);
  PileBody body;
  if (lying) {
    p.pose.linear() =
        Eigen::AngleAxisf(kPi / 2.0f, Vector3f::UnitY()).toRotationMatrix();
    p.pose.translation() = Vector3f(0, 0, r);
    body.hull = Rect(Vector2f::Zero(), Vector2f(*hz, r), 0.0f, 2.0f * r);
  } else {
    p.pose.translation() = Vector3f(0, 0, *hz);
    body.hull = Disc(r, 0.0f, 2.0f * *hz);
  }
  body.primitives.push_back(p);
  body.solids = {body.hull};
  return body;
}

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

Footprint PoseFootprint(Footprint f, const Vector2f& xy, float base_z,
                        float yaw) {
  f.centre = xy + Eigen::Rotation2Df(yaw) * f.centre;
  f.yaw += yaw;
  f.z_min += base_z;
  f.z_max += base_z;
  return f;
}

}  // namespace

Primitive BoxPrimitive(const Vector3f& centre, const Vector3f& half,
                       const Vector3f& rgb, Texture texture) {
  Primitive p;
  p.shape = Shape::kBox;
  p.pose.translation() = centre;
  p.half_extents = half;
  p.rgb = rgb;
  p.texture = texture;
  return p;
}

std::optional<PileBody> MakePileBody(StackedKind kind, float room,
                                     const Vector3f& table_rgb, Random& rng) {
  std::optional<PileBody> body;
  const bool on_table = room == std::numeric_limits<float>::infinity();
  switch (kind) {
    case StackedKind::kBook:
      body = MakeBook(room, table_rgb, rng);
      break;
    case StackedKind::kBox:
      body = MakeBox(room, !on_table, table_rgb, rng);
      break;
    case StackedKind::kCup:
      body = MakeCup(room, table_rgb, rng);
      break;
    case StackedKind::kMug:
      body = MakeMug(room, table_rgb, rng);
      break;
    case StackedKind::kBowl:
      body = MakeBowl(room, table_rgb, rng);
      break;
    case StackedKind::kOpenBox:
      if (on_table) body = MakeOpenBox(table_rgb, rng);
      break;
    case StackedKind::kCan:
      body = MakeCan(room, table_rgb, rng);
      break;
    case StackedKind::kPlate:
      body = MakePlate(room, table_rgb, rng);
      break;
    case StackedKind::kTablet:
      body = MakeTablet(room, rng);
      break;
    case StackedKind::kDrill:
      if (on_table) body = MakeDrill(room, table_rgb, rng);
      break;
    case StackedKind::kBanana:
      body = MakeBanana(room, rng);
      break;
    case StackedKind::kPen:
      body = MakePen(room, table_rgb, rng);
      break;
    case StackedKind::kPart:
      body = MakePart(room, table_rgb, rng);
      break;
  }
  if (body.has_value()) body->kind = kind;
  return body;
}

bool CanRestOn(StackedKind kind, StackedKind support) {
  using K = StackedKind;
  switch (support) {
    case K::kBook:
      return kind != K::kOpenBox;
    case K::kBox:
      return kind == K::kBox || kind == K::kCup || kind == K::kCan ||
             kind == K::kPen || kind == K::kPart;
    case K::kTablet:
      return kind == K::kBox || kind == K::kCup || kind == K::kMug ||
             kind == K::kCan || kind == K::kPen || kind == K::kPart ||
             kind == K::kBanana;
    case K::kPlate:
      return kind == K::kCup || kind == K::kMug || kind == K::kBanana ||
             kind == K::kPart;
    case K::kBowl:
      return kind == K::kCup;
    case K::kOpenBox:
      return kind == K::kBox || kind == K::kCup || kind == K::kMug ||
             kind == K::kCan;
    default:
      return false;
  }
}

std::string_view StackedKindName(StackedKind kind) {
  switch (kind) {
    case StackedKind::kBook:
      return "book";
    case StackedKind::kBox:
      return "box";
    case StackedKind::kCup:
      return "cup";
    case StackedKind::kMug:
      return "mug";
    case StackedKind::kBowl:
      return "bowl";
    case StackedKind::kOpenBox:
      return "open_box";
    case StackedKind::kCan:
      return "can";
    case StackedKind::kPlate:
      return "plate";
    case StackedKind::kTablet:
      return "tablet";
    case StackedKind::kDrill:
      return "drill";
    case StackedKind::kBanana:
      return "banana";
    case StackedKind::kPen:
      return "pen";
    case StackedKind::kPart:
      return "part";
  }
  return "unknown";
}

PileBody PosePileBody(const PileBody& body, const Vector2f& xy, float base_z,
                      float yaw) {
  PileBody out = body;
  Eigen::Isometry3f move = Eigen::Isometry3f::Identity();
  move.linear() = Eigen::AngleAxisf(yaw, Vector3f::UnitZ()).toRotationMatrix();
  move.translation() = Vector3f(xy.x(), xy.y(), base_z);
  for (Primitive& p : out.primitives) p.pose = move * p.pose;
  for (Footprint& f : out.solids) f = PoseFootprint(f, xy, base_z, yaw);
  out.hull = PoseFootprint(body.hull, xy, base_z, yaw);
  if (out.top.has_value()) {
    out.top = PoseFootprint(*body.top, xy, base_z, yaw);
  }
  return out;
}

bool FitsInside(const Footprint& f, const Footprint& area) {
  if (!area.is_circle) return FitsOnTop(f, area);
  if (f.is_circle) {
    return (f.centre - area.centre).norm() + f.radius <= area.radius;
  }
  for (const float sx : {-1.0f, 1.0f}) {
    for (const float sy : {-1.0f, 1.0f}) {
      const Vector2f corner =
          f.centre + sx * f.half.x() * f.AxisX() + sy * f.half.y() * f.AxisY();
      if ((corner - area.centre).norm() > area.radius) return false;
    }
  }
  return true;
}

}  // namespace fovea::synth
