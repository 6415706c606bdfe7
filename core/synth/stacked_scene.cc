// RandomStackedPileSpec: compact piles of household objects resting on each
// other.
//
// A pile is built one object at a time from a plan: groups of steps (a book
// and what lies on it, an open box and its contents, a bowl and the cup in
// it, a mug, a can, a plate or tablet and what stands on it, a box and the
// box on it) in random order, then random fillers until the drawn number
// of objects stands. A step names a kind and where it goes: on the table
// (next to an object already there, or anywhere in the pile's area) or on
// the top of an object of a kind that can carry it. A proposal is kept if
// its hull lies within the support's top (or on the table) and in view, its
// solids collide with no other object's solids (stacked_bodies.h), and
// after it every object keeps a share of its pixels on a half-resolution
// ray cast.

#include "core/synth/stacked_scene.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/strings.h"
#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/raycast.h"
#include "core/synth/room.h"
#include "core/synth/stacked_bodies.h"
#include "core/synth/synth_scene.h"
#include "core/synth/textures.h"

namespace fovea::synth {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

constexpr float kPi = 3.14159265358979f;
constexpr float kInf = std::numeric_limits<float>::infinity();
// Stream id mixed into the seed, so the pile does not share its draws with
// a room or pile of the same seed; each further round adds kRoundStep.
constexpr uint64_t kPileStream = 0x737461636bULL;  // "stack"
constexpr uint64_t kRoundStep = 0x9e3779b97f4a7c15ULL;
constexpr int kMaxRounds = 8;

constexpr int kMinObjects = 8;
constexpr int kMaxObjects = 16;
constexpr int kMinStacked = 3;

// Camera, metres: height above the table, distance back from the pile's
// centre, sideways offset, the height it looks at, roll (radians).
constexpr float kEyeHeightMin = 0.6f, kEyeHeightMax = 0.8f;
constexpr float kEyeBackMin = 0.5f, kEyeBackMax = 0.8f;
constexpr float kEyeSideMax = 0.12f;
constexpr float kLookAtHeight = 0.04f;
constexpr float kRollMax = 3.0f * kPi / 180.0f;
// From above (StackedPileOptions::from_above): height and distance back.
constexpr float kAboveHeightMin = 0.6f, kAboveHeightMax = 0.9f;
constexpr float kAboveBackMax = 0.25f;

// The table and the room, metres.
constexpr float kTableHalfXMin = 0.75f, kTableHalfXMax = 1.0f;
constexpr float kTableHalfYMin = 0.5f, kTableHalfYMax = 0.65f;
constexpr float kTableThicknessMin = 0.025f, kTableThicknessMax = 0.04f;
constexpr float kTopRecess = 0.0005f;  // the edge slab below the top
constexpr float kTableHeightMin = 0.72f, kTableHeightMax = 0.78f;
constexpr float kWallGapMax = 0.3f;  // behind the table's back edge
constexpr float kWallHalfThickness = 0.025f;
constexpr float kWallHalfHeight = 1.3f;
constexpr float kRoomHalfSize = 4.0f;
// The pile's centre on the table (x within +-, y in [min, max]).
constexpr float kPileCentreX = 0.15f;
constexpr float kPileCentreYMin = -0.12f, kPileCentreYMax = 0.05f;

// Placement, metres.
const Vector2f kPileHalf(0.2f, 0.14f);    // free positions around the centre
constexpr float kNearProbability = 0.7f;  // next to an object on the table
constexpr float kNearGapMin = 0.003f, kNearGapMax = 0.04f;
constexpr float kClearance = 0.002f;  // between solids of different objects
constexpr float kTableMargin = 0.05f;
constexpr float kStackedYawMax = 0.35f;  // radians, relative to a support
constexpr float kFillerStackProbability = 0.6f;
constexpr int kAttemptsPerStep = 30;
constexpr int kMaxFillerSteps = 40;
constexpr float kViewMarginPx = 6.0f;
// Visibility, checked on a ray cast of at most this width (half of 640):
// every object keeps this share of its pixels alone, and this many pixels.
constexpr int kVisibilityCastWidth = 320;
constexpr float kMinVisibleFraction = 0.35f;
constexpr int kMinVisiblePixelsHalfRes = 45;

// Filler kinds and their weights.
constexpr StackedKind kFillerKinds[] = {
    StackedKind::kBook,  StackedKind::kBox,   StackedKind::kCup,
    StackedKind::kMug,   StackedKind::kBowl,  StackedKind::kCan,
    StackedKind::kPlate, StackedKind::kTablet};
constexpr float kFillerWeights[] = {0.16f, 0.3f,  0.1f,  0.1f,
                                    0.06f, 0.18f, 0.05f, 0.05f};

// Where a step puts its object.
// kOnLast: on the object placed just before (a tower's next storey).
enum class Where { kTable, kOnKind, kAnywhere, kOnLast };

struct Step {
  StackedKind kind;
  Where where = Where::kTable;
  StackedKind on = StackedKind::kBook;  // with Where::kOnKind
};

struct Placed {
  PileBody body;
  int rests_on = -1;
};

StackedKind DrawFillerKind(Random& rng) {
  float r = static_cast<float>(rng.Uniform());
  for (size_t i = 0; i + 1 < std::size(kFillerKinds); ++i) {
    if ((r -= kFillerWeights[i]) < 0.0f) return kFillerKinds[i];
  }
  return kFillerKinds[std::size(kFillerKinds) - 1];
}

// The plan: a book on the table, the open box and its contents, then the
// other groups in random order.
std::vector<Step> Plan(const StackedPileOptions& options, Random& rng) {
  using K = StackedKind;
  std::vector<std::vector<Step>> groups;
  std::vector<Step> books;
  if (rng.Bernoulli(0.6)) books.push_back({K::kBook, Where::kOnKind, K::kBook});
  books.push_back({K::kBox, Where::kOnKind, K::kBook});
  groups.push_back(books);
  std::vector<Step> open_box;  // first: it needs the most room
  if (rng.Bernoulli(0.7)) {
    open_box = {{K::kOpenBox, Where::kTable}};
    const int inside = rng.UniformInt(1, 3);
    constexpr K kInside[] = {K::kBox, K::kCan, K::kCup, K::kMug};
    for (int i = 0; i < inside; ++i) {
      open_box.push_back(
          {kInside[rng.UniformInt(0, 3)], Where::kOnKind, K::kOpenBox});
    }
  }
  if (rng.Bernoulli(0.8)) {
    std::vector<Step> bowl = {{K::kBowl, Where::kTable}};
    if (rng.Bernoulli(0.85))
      bowl.push_back({K::kCup, Where::kOnKind, K::kBowl});
    groups.push_back(bowl);
  }
  if (rng.Bernoulli(0.75)) groups.push_back({{K::kMug, Where::kAnywhere}});
  if (rng.Bernoulli(0.7)) groups.push_back({{K::kCan, Where::kAnywhere}});
  if (rng.Bernoulli(0.6)) {
    const K thin = rng.Bernoulli(0.5) ? K::kPlate : K::kTablet;
    std::vector<Step> group = {{thin, Where::kTable}};
    if (rng.Bernoulli(0.5)) {
      group.push_back(
          {rng.Bernoulli(0.5) ? K::kCup : K::kMug, Where::kOnKind, thin});
    }
    groups.push_back(group);
  }
  groups.push_back(
      {{K::kBox, Where::kTable}, {K::kBox, Where::kOnKind, K::kBox}});
  // What real frames showed cut or missed: a tower, a drill, a banana, a
  // pen and small parts (on the table or on a book, a box or a plate);
  // placed before the other groups, so that a pile's object count does not
  // cut them off.
  std::vector<std::vector<Step>> more;
  if (options.more_kinds) {
    if (rng.Bernoulli(0.7)) {
      more.push_back({{K::kBox, Where::kTable},
                      {K::kBox, Where::kOnLast},
                      {K::kBox, Where::kOnLast}});
    }
    if (rng.Bernoulli(0.6)) more.push_back({{K::kDrill, Where::kTable}});
    if (rng.Bernoulli(0.6)) more.push_back({{K::kBanana, Where::kAnywhere}});
    if (rng.Bernoulli(0.7)) more.push_back({{K::kPen, Where::kAnywhere}});
    const int parts = rng.UniformInt(1, 2);
    for (int i = 0; i < parts; ++i) {
      more.push_back({{K::kPart, Where::kAnywhere}});
    }
  }
  for (size_t i = groups.size() - 1; i > 0; --i) {
    std::swap(groups[i], groups[rng.UniformInt(0, static_cast<int>(i))]);
  }
  std::vector<Step> plan = {{K::kBook, Where::kTable}};
  plan.insert(plan.end(), open_box.begin(), open_box.end());
  for (const std::vector<Step>& group : more) {
    plan.insert(plan.end(), group.begin(), group.end());
  }
  for (const std::vector<Step>& group : groups) {
    plan.insert(plan.end(), group.begin(), group.end());
  }
  return plan;
}

// The table, the camera and the room around them.
SceneSpec Stage(RoomSensor sensor, const StackedPileOptions& options,
                Random& rng, Vector2f* pile_centre) {
  SceneSpec spec;
  spec.width = options.width;
  spec.height = options.height;
  spec.intrinsics = SensorIntrinsics(sensor, options.width, options.height);
  spec.table_half_size = Vector2f(rng.Uniform(kTableHalfXMin, kTableHalfXMax),
                                  rng.Uniform(kTableHalfYMin, kTableHalfYMax));
  // Oak to walnut: brown, not orange.
  const float red = rng.Uniform(0.45f, 0.65f);
  spec.table_rgb = Vector3f(red, red * rng.Uniform(0.72f, 0.8f),
                            red * rng.Uniform(0.5f, 0.6f));
  spec.table_texture = Texture::kWood;
  *pile_centre = Vector2f(rng.Uniform(-kPileCentreX, kPileCentreX),
                          rng.Uniform(kPileCentreYMin, kPileCentreYMax));
  const Vector3f eye =
      options.from_above
          ? Vector3f(pile_centre->x() + rng.Uniform(-kEyeSideMax, kEyeSideMax),
                     pile_centre->y() - rng.Uniform(0.0f, kAboveBackMax),
                     rng.Uniform(kAboveHeightMin, kAboveHeightMax))
          : Vector3f(pile_centre->x() + rng.Uniform(-kEyeSideMax, kEyeSideMax),
                     pile_centre->y() - rng.Uniform(kEyeBackMin, kEyeBackMax),
                     rng.Uniform(kEyeHeightMin, kEyeHeightMax));
  spec.camera_pose =
      LookAt(eye, Vector3f(pile_centre->x(), pile_centre->y(), kLookAtHeight));
  spec.camera_pose.linear() =
      spec.camera_pose.linear() *
      Eigen::AngleAxisf(rng.Uniform(-kRollMax, kRollMax), Vector3f::UnitZ())
          .toRotationMatrix();

  const Vector2f& half = spec.table_half_size;
  const float thickness = rng.Uniform(kTableThicknessMin, kTableThicknessMax);
  const float floor_z = -rng.Uniform(kTableHeightMin, kTableHeightMax);
  spec.background.push_back(
      {BoxPrimitive(Vector3f(0, 0, -kTopRecess - thickness / 2),
                    Vector3f(half.x(), half.y(), thickness / 2),
                    spec.table_rgb * 0.9f, Texture::kWood),
       kSupportTableLabel});
  const float grey = rng.Uniform(0.45f, 0.65f);
  spec.background.push_back(
      {BoxPrimitive(Vector3f(0, 0, floor_z - 0.01f),
                    Vector3f(kRoomHalfSize, kRoomHalfSize, 0.01f),
                    Vector3f(grey, grey, grey * 1.03f), Texture::kPaint),
       kFloorLabel});
  const float wall_y =
      half.y() + rng.Uniform(0.0f, kWallGapMax) + kWallHalfThickness;
  const float wall = rng.Uniform(0.7f, 0.9f);
  spec.background.push_back(
      {BoxPrimitive(
           Vector3f(0, wall_y, floor_z + kWallHalfHeight),
           Vector3f(kRoomHalfSize, kWallHalfThickness, kWallHalfHeight),
           Vector3f(wall, wall * 0.98f, wall * 0.93f), Texture::kPaint),
       kWallLabel});
  return spec;
}

// The placed bodies as spec objects and object parts.
void SetObjects(const std::vector<Placed>& placed, SceneSpec& spec) {
  spec.objects.clear();
  spec.object_parts.clear();
  for (const Placed& p : placed) {
    const int index = static_cast<int>(spec.objects.size());
    spec.objects.push_back(p.body.primitives[0]);
    for (size_t i = 1; i < p.body.primitives.size(); ++i) {
      spec.object_parts.push_back({p.body.primitives[i], index});
    }
  }
}

// Whether, with `candidate` added, every object keeps its share of the
// pixels it covers alone (`alone`, extended with the candidate's on
// success).
bool KeepsEveryObjectVisible(const Placed& candidate,
                             const std::vector<Placed>& placed,
                             const SceneSpec& spec, std::vector<int>& alone) {
  SceneSpec trial = spec;
  SetObjects({candidate}, trial);
  const int candidate_alone =
      ReducedObjectPixelCounts(trial, kVisibilityCastWidth)[0];
  std::vector<Placed> all = placed;
  all.push_back(candidate);
  SetObjects(all, trial);
  const std::vector<int> counts =
      ReducedObjectPixelCounts(trial, kVisibilityCastWidth);
  for (size_t i = 0; i < counts.size(); ++i) {
    const int full = i < alone.size() ? alone[i] : candidate_alone;
    if (counts[i] < kMinVisiblePixelsHalfRes ||
        counts[i] < kMinVisibleFraction * full) {
      return false;
    }
  }
  alone.push_back(candidate_alone);
  return true;
}

// Whether the hull lies on the table and projects inside the image.
bool OnTableAndInView(const Footprint& hull, const SceneSpec& spec) {
  const Vector2f reach = hull.centre.cwiseAbs() + AabbHalf(hull);
  if (reach.x() > spec.table_half_size.x() - kTableMargin ||
      reach.y() > spec.table_half_size.y() - kTableMargin) {
    return false;
  }
  std::vector<Vector2f> outline;
  if (hull.is_circle) {
    for (int i = 0; i < 8; ++i) {
      const float a = 2.0f * kPi * static_cast<float>(i) / 8.0f;
      outline.push_back(hull.centre +
                        hull.radius * Vector2f(std::cos(a), std::sin(a)));
    }
  } else {
    for (const float sx : {-1.0f, 1.0f}) {
      for (const float sy : {-1.0f, 1.0f}) {
        outline.push_back(hull.centre + sx * hull.half.x() * hull.AxisX() +
                          sy * hull.half.y() * hull.AxisY());
      }
    }
  }
  const Eigen::Isometry3f world_to_camera = spec.camera_pose.inverse();
  const Intrinsics& k = spec.intrinsics;
  for (const float z : {hull.z_min, hull.z_max}) {
    for (const Vector2f& xy : outline) {
      const Vector3f p = world_to_camera * Vector3f(xy.x(), xy.y(), z);
      if (p.z() < 0.1f) return false;
      const float u = static_cast<float>(k.fx) * p.x() / p.z() + k.cx;
      const float v = static_cast<float>(k.fy) * p.y() / p.z() + k.cy;
      if (u < kViewMarginPx || u > spec.width - 1 - kViewMarginPx ||
          v < kViewMarginPx || v > spec.height - 1 - kViewMarginPx) {
        return false;
      }
    }
  }
  return true;
}

// Whether `candidate` comes closer than kClearance to a solid of another
// object (a bowl's contents are kept clear of it by its top instead).
bool CollidesWithAny(const Placed& candidate,
                     const std::vector<Placed>& placed) {
  for (size_t j = 0; j < placed.size(); ++j) {
    if (candidate.rests_on == static_cast<int>(j) && placed[j].body.cavity) {
      continue;
    }
    for (const Footprint& a : candidate.body.solids) {
      for (const Footprint& b : placed[j].body.solids) {
        if (Collides(a, b, kClearance)) return true;
      }
    }
  }
  return false;
}

// The objects a body of `kind` may rest on for `step`.
std::vector<int> Supports(const Step& step, const std::vector<Placed>& placed) {
  std::vector<int> out;
  if (step.where == Where::kOnLast) {
    if (!placed.empty()) {
      const PileBody& b = placed.back().body;
      if (b.top.has_value() && CanRestOn(step.kind, b.kind)) {
        out.push_back(static_cast<int>(placed.size()) - 1);
      }
    }
    return out;
  }
  for (size_t j = 0; j < placed.size(); ++j) {
    const PileBody& b = placed[j].body;
    if (!b.top.has_value() || !CanRestOn(step.kind, b.kind)) continue;
    if (step.where == Where::kOnKind && b.kind != step.on) continue;
    out.push_back(static_cast<int>(j));
  }
  return out;
}

// One proposal for `step`, not yet checked against the other objects.
std::optional<Placed> Propose(const Step& step,
                              const std::vector<Placed>& placed,
                              const Vector2f& pile_centre,
                              const Vector3f& table_rgb, Random& rng) {
  int support = -1;
  if (step.where != Where::kTable) {
    const std::vector<int> supports = Supports(step, placed);
    const bool must_stack =
        step.where == Where::kOnKind || step.where == Where::kOnLast;
    const bool stack = must_stack || rng.Bernoulli(kFillerStackProbability);
    if (stack && supports.empty() && must_stack) return std::nullopt;
    if (stack && !supports.empty()) {
      support =
          supports[rng.UniformInt(0, static_cast<int>(supports.size()) - 1)];
    }
  }
  if (support < 0) {
    std::optional<PileBody> body =
        MakePileBody(step.kind, kInf, table_rgb, rng);
    if (!body.has_value()) return std::nullopt;
    const float yaw = rng.Uniform(0.0f, 2.0f * kPi);
    std::vector<int> on_table;
    for (size_t j = 0; j < placed.size(); ++j) {
      if (placed[j].rests_on < 0) on_table.push_back(static_cast<int>(j));
    }
    Vector2f xy =
        pile_centre + Vector2f(rng.Uniform(-1.0f, 1.0f) * kPileHalf.x(),
                               rng.Uniform(-1.0f, 1.0f) * kPileHalf.y());
    if (!on_table.empty() && rng.Bernoulli(kNearProbability)) {
      const Footprint& other =
          placed[on_table[rng.UniformInt(
                     0, static_cast<int>(on_table.size()) - 1)]]
              .body.hull;
      const float angle = rng.Uniform(0.0f, 2.0f * kPi);
      const Vector2f dir(std::cos(angle), std::sin(angle));
      const Footprint at_other =
          PosePileBody(*body, other.centre, 0.0f, yaw).hull;
      xy = other.centre + (ContactDistance(other, at_other, other.centre, dir) +
                           rng.Uniform(kNearGapMin, kNearGapMax)) *
                              dir;
    }
    // Keeps the pile compact and centred in the image.
    if (((xy - pile_centre).cwiseAbs() - kPileHalf).maxCoeff() > 0.0f) {
      return std::nullopt;
    }
    return Placed{PosePileBody(*body, xy, 0.0f, yaw), -1};
  }
  const Footprint& area = *placed[support].body.top;
  const bool flat_body =
      step.kind == StackedKind::kBook || step.kind == StackedKind::kTablet;
  const float room = area.is_circle ? area.radius
                     : flat_body    ? area.half.maxCoeff()
                                    : area.half.minCoeff();
  std::optional<PileBody> body = MakePileBody(step.kind, room, table_rgb, rng);
  if (!body.has_value()) return std::nullopt;
  float yaw = rng.Uniform(0.0f, 2.0f * kPi);
  Vector2f xy = area.centre;
  if (area.is_circle) {
    const float slack =
        std::max(0.0f, area.radius - body->hull.BoundingRadius());
    const float a = rng.Uniform(0.0f, 2.0f * kPi);
    xy += std::sqrt(static_cast<float>(rng.Uniform())) * slack *
          Vector2f(std::cos(a), std::sin(a));
  } else {
    yaw = area.yaw + rng.Uniform(-kStackedYawMax, kStackedYawMax) +
          (rng.Bernoulli(0.5) ? kPi / 2.0f : 0.0f);
    xy += rng.Uniform(-1.0f, 1.0f) * area.half.x() * area.AxisX() +
          rng.Uniform(-1.0f, 1.0f) * area.half.y() * area.AxisY();
  }
  Placed out{PosePileBody(*body, xy, area.z_min, yaw), support};
  if (!FitsInside(out.body.hull, area)) return std::nullopt;
  return out;
}

// Places `step`'s object, trying up to kAttemptsPerStep proposals.
void PlaceStep(const Step& step, const Vector2f& pile_centre,
               const SceneSpec& spec, Random& rng, std::vector<Placed>& placed,
               std::vector<int>& alone) {
  for (int attempt = 0; attempt < kAttemptsPerStep; ++attempt) {
    const std::optional<Placed> c =
        Propose(step, placed, pile_centre, spec.table_rgb, rng);
    if (!c.has_value() || !OnTableAndInView(c->body.hull, spec) ||
        CollidesWithAny(*c, placed) ||
        !KeepsEveryObjectVisible(*c, placed, spec, alone)) {
      continue;
    }
    placed.push_back(*c);
    return;
  }
}

// Turns the camera about its centre to look at the middle of the placed
// hulls, if every hull stays in view. A rotation about the eye changes no
// occlusion, so the visible shares checked while placing still hold.
void AimAtPile(const std::vector<Placed>& placed, SceneSpec& spec) {
  if (placed.empty()) return;
  Vector2f lo = Vector2f::Constant(kInf), hi = Vector2f::Constant(-kInf);
  for (const Placed& p : placed) {
    const Vector2f half = AabbHalf(p.body.hull);
    lo = lo.cwiseMin(p.body.hull.centre - half);
    hi = hi.cwiseMax(p.body.hull.centre + half);
  }
  const Vector2f middle = (lo + hi) / 2.0f;
  const Eigen::Isometry3f before = spec.camera_pose;
  const Eigen::Isometry3f level = LookAt(
      before.translation(), Vector3f(middle.x(), middle.y(), kLookAtHeight));
  // Keep the roll: the old pose is LookAt's times a turn about camera z.
  const Eigen::Isometry3f old_level = LookAt(
      before.translation(), before.translation() + before.linear().col(2));
  spec.camera_pose.linear() =
      level.linear() * (old_level.linear().transpose() * before.linear());
  for (const Placed& p : placed) {
    if (!OnTableAndInView(p.body.hull, spec)) {
      spec.camera_pose = before;
      return;
    }
  }
}

// One round of drawing a pile from `rng`.
StackedPileSpec DrawPile(RoomSensor sensor, const StackedPileOptions& options,
                         Random& rng) {
  Vector2f pile_centre;
  StackedPileSpec out;
  out.spec = Stage(sensor, options, rng, &pile_centre);
  const int wanted = rng.UniformInt(kMinObjects, kMaxObjects);
  std::vector<Placed> placed;
  std::vector<int> alone;
  for (const Step& step : Plan(options, rng)) {
    if (static_cast<int>(placed.size()) >= wanted) break;
    PlaceStep(step, pile_centre, out.spec, rng, placed, alone);
  }
  for (int i = 0;
       static_cast<int>(placed.size()) < wanted && i < kMaxFillerSteps; ++i) {
    PlaceStep({DrawFillerKind(rng), Where::kAnywhere}, pile_centre, out.spec,
              rng, placed, alone);
  }
  AimAtPile(placed, out.spec);
  SetObjects(placed, out.spec);
  for (const Placed& p : placed) {
    out.kinds.push_back(p.body.kind);
    out.rests_on.push_back(p.rests_on);
  }
  return out;
}

bool IsComplete(const StackedPileSpec& pile) {
  return static_cast<int>(pile.kinds.size()) >= kMinObjects &&
         CountStacked(pile.rests_on) >= kMinStacked &&
         !pile.spec.object_parts.empty();
}

}  // namespace

int CountStacked(const std::vector<int>& rests_on) {
  return static_cast<int>(
      std::count_if(rests_on.begin(), rests_on.end(),
                    [](int support) { return support >= 0; }));
}

StackedPileSpec RandomStackedPileSpec(uint64_t seed, RoomSensor sensor) {
  return RandomStackedPileSpec(seed, sensor, SensorPileOptions(sensor));
}

StackedPileSpec RandomStackedPileSpec(uint64_t seed, RoomSensor sensor,
                                      const StackedPileOptions& options) {
  FOVEA_CHECK(Validate(options).ok());
  StackedPileSpec pile;
  for (int round = 0; round < kMaxRounds; ++round) {
    Random rng(seed ^
               (kPileStream + kRoundStep * static_cast<uint64_t>(round)));
    pile = DrawPile(sensor, options, rng);
    if (IsComplete(pile)) break;
  }
  FOVEA_CHECK(Validate(pile.spec).ok());
  return pile;
}

StackedPile GenerateStackedPile(uint64_t seed, RoomSensor sensor) {
  return GenerateStackedPile(seed, sensor, SensorPileOptions(sensor));
}

StackedPile GenerateStackedPile(uint64_t seed, RoomSensor sensor,
                                const StackedPileOptions& options) {
  StackedPileSpec pile = RandomStackedPileSpec(seed, sensor, options);
  AddPrints(seed, kPrintedObjectShare, pile.spec);
  StackedPile out;
  out.scene = RenderScene(pile.spec, RoomNoise(sensor), seed);
  out.scene.frame.name =
      absl::StrCat(options.from_above ? "stack-above-" : "stack-",
                   AbslView(RoomSensorTag(sensor)), seed);
  out.spec = std::move(pile.spec);
  out.kinds = std::move(pile.kinds);
  out.rests_on = std::move(pile.rests_on);
  return out;
}

}  // namespace fovea::synth
