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
#include "core/synth/stacked_bodies_internal.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using pile_internal::Capped;
using pile_internal::Disc;
using pile_internal::kPi;
using pile_internal::kSlate;
using pile_internal::MakeBanana;
using pile_internal::MakeDrill;
using pile_internal::MakePart;
using pile_internal::MakePen;
using pile_internal::Pick;
using pile_internal::Rect;
using pile_internal::Rgb;
using pile_internal::SetBoxVolumes;

using Eigen::Vector2f;
using Eigen::Vector3f;

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
