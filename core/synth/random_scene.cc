// RandomSceneSpec and LookAt: random, physically resting table-top scenes.
//
// Objects are placed one at a time. Each proposal is free (anywhere in a
// work area around the camera's look-at point), stacked (on top of a box),
// touching (in contact with an object on the table) or occluding (between
// the camera and an object on the table). A proposal is kept if its footprint
// lies on the table and in view, it does not collide with any object placed
// before (conservative test on vertical projections, see Collides), and after
// it every object keeps a share of its pixels (checked on a half-resolution ray
// cast).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "core/base/check.h"
#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/random_bodies.h"
#include "core/synth/raycast.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

constexpr float kPi = 3.14159265358979f;
constexpr int kMaxObjects = 20;

// Objects stacked on a box: at most this tall (half height, metres);
// stacked cylinders at least this thick (radius, metres).
constexpr float kStackedHalfHeightMax = 0.05f;
constexpr float kStackedRadiusMin = 0.015f;
constexpr float kStackedYawMax = 0.35f;         // radians, relative to support
constexpr float kStackedBoxProbability = 0.6f;  // else an upright cylinder
constexpr float kMinSupportHalfSize = 0.025f;   // metres

// Leaning boxes: tilt, radians.
constexpr float kMinLean = 0.21f;  // 12 degrees
constexpr float kMaxLean = 0.52f;  // 30 degrees

// Placement, metres.
constexpr float kTableMargin = 0.03f;  // footprints keep off the edge
// Free objects go within this of the camera's look-at point (x, y), where
// they are seen large and near the image centre, as in OSD.
const Vector2f kWorkAreaHalf(0.32f, 0.24f);
constexpr float kFreeClearance = 0.015f;   // gap around free objects
constexpr float kContactGap = 0.001f;      // "touching": float-safe contact
constexpr float kOcclusionGapMin = 0.02f;  // occluder in front of target
constexpr float kOcclusionGapMax = 0.08f;
constexpr float kOcclusionLateralShare = 0.6f;  // of the target's radius
// Footprint corners must project this far inside the image, pixels.
constexpr float kViewMarginPx = 8.0f;
constexpr int kAttemptsPerObject = 40;
// Minimum pixels of every object on the half-resolution visibility render,
// which is at most this wide.
constexpr int kMinVisiblePixelsHalfRes = 40;
constexpr int kVisibilityCastWidth = 320;

struct Placed {
  Primitive primitive;
  Footprint footprint;
  bool on_table = true;
  bool carries = false;  // a box with something stacked on it
};

// `body` resting at table position `xy` on the plane z = `base_z`, turned
// by `yaw` about +z.
Placed Pose(const Body& body, const Vector2f& xy, float base_z, float yaw) {
  Placed out;
  Primitive& p = out.primitive;
  p.shape = body.shape;
  p.half_extents = body.half_extents;
  p.radius = body.radius;
  p.thickness = body.thickness;
  p.floor_height = body.floor_height;
  p.rgb = body.rgb;
  Eigen::Matrix3f rotation =
      Eigen::AngleAxisf(yaw, Vector3f::UnitZ()).toRotationMatrix();
  if (body.lying) {  // local z (the axis) along the yawed world x
    rotation = rotation * Eigen::AngleAxisf(kPi / 2.0f, Vector3f::UnitY());
  }
  if (body.lean != 0.0f) {  // leaning over towards the yawed world x
    rotation = rotation * Eigen::AngleAxisf(body.lean, Vector3f::UnitY());
  }
  p.pose = Eigen::Isometry3f::Identity();
  p.pose.linear() = rotation;
  p.pose.translation() = Vector3f(xy.x(), xy.y(), base_z + body.Height() / 2);

  Footprint& f = out.footprint;
  f.centre = xy;
  f.yaw = yaw;
  f.z_min = base_z;
  f.z_max = base_z + body.Height();
  if (body.shape == Shape::kBox) {
    f.is_circle = false;
    f.half = body.half_extents.head<2>();
    if (body.lean != 0.0f) {  // the tilted box's vertical projection
      f.half.x() = body.half_extents.x() * std::cos(body.lean) +
                   body.half_extents.z() * std::sin(body.lean);
    }
  } else if (body.lying) {
    f.is_circle = false;
    f.half = Vector2f(body.half_extents.z(), body.radius);
  } else {
    f.radius = body.radius;
  }
  out.on_table = base_z == 0.0f;
  return out;
}

// A proposed object, with the clearance it must keep from every other
// object and the index of the box it stands on (or -1).
struct Candidate {
  Placed placed;
  float clearance = kFreeClearance;
  int support = -1;
};

// Anywhere in the work area around `target` (the camera's look-at point on
// the table); Admissible() rejects what is off the table.
Candidate ProposeFree(const Vector2f& target, const Body& body, float scale,
                      Random& rng) {
  const Vector2f half = kWorkAreaHalf * scale;
  const Vector2f xy = target + Vector2f(rng.Uniform(-half.x(), half.x()),
                                        rng.Uniform(-half.y(), half.y()));
  return {Pose(body, xy, 0.0f, rng.Uniform(0.0f, 2.0f * kPi)), kFreeClearance,
          -1};
}

std::optional<Candidate> ProposeStacked(const std::vector<Placed>& placed,
                                        const Vector3f& rgb, Random& rng) {
  std::vector<int> supports;
  for (size_t i = 0; i < placed.size(); ++i) {
    const Placed& p = placed[i];
    if (p.primitive.shape == Shape::kBox && !p.carries &&
        p.footprint.half.minCoeff() >= kMinSupportHalfSize) {
      supports.push_back(static_cast<int>(i));
    }
  }
  if (supports.empty()) return std::nullopt;
  const int s =
      supports[rng.UniformInt(0, static_cast<int>(supports.size()) - 1)];
  const Footprint& top = placed[s].footprint;
  // Sized to fit the top face; `reach` is the new footprint's half extent
  // along the support's axes, the slack what is left for an offset.
  Body body;
  body.rgb = rgb;
  float relative_yaw = 0.0f;
  Vector2f reach;
  if (rng.Bernoulli(kStackedBoxProbability)) {
    body.shape = Shape::kBox;
    relative_yaw = rng.Uniform(-kStackedYawMax, kStackedYawMax);
    const float c = std::cos(relative_yaw);
    const float sn = std::abs(std::sin(relative_yaw));
    // The largest box of this yaw whose x:y ratio follows the support's.
    const float scale =
        rng.Uniform(0.5f, 0.95f) /
        std::max((c * top.half.x() + sn * top.half.y()) / top.half.x(),
                 (sn * top.half.x() + c * top.half.y()) / top.half.y());
    body.half_extents = {std::max(kBoxHalfMin, scale * top.half.x()),
                         std::max(kBoxHalfMin, scale * top.half.y()),
                         rng.Uniform(kBoxHalfMin, kStackedHalfHeightMax)};
    reach = {c * body.half_extents.x() + sn * body.half_extents.y(),
             sn * body.half_extents.x() + c * body.half_extents.y()};
  } else {
    body.shape = Shape::kCylinder;
    body.radius = rng.Uniform(kStackedRadiusMin, 0.9f * top.half.minCoeff());
    body.half_extents = {
        body.radius, body.radius,
        rng.Uniform(kCylinderHalfHeightMin, kStackedHalfHeightMax)};
    reach = Vector2f::Constant(body.radius);
  }
  const Vector2f slack = (top.half - reach).cwiseMax(0.0f);
  const Vector2f offset(rng.Uniform(-slack.x(), slack.x()),
                        rng.Uniform(-slack.y(), slack.y()));
  const Vector2f xy =
      top.centre + offset.x() * top.AxisX() + offset.y() * top.AxisY();
  const float yaw = top.yaw + relative_yaw;
  Candidate c{Pose(body, xy, top.z_max, yaw), kContactGap / 2.0f, s};
  if (!FitsOnTop(c.placed.footprint, top)) return std::nullopt;
  return c;
}

std::vector<int> OnTable(const std::vector<Placed>& placed) {
  std::vector<int> out;
  for (size_t i = 0; i < placed.size(); ++i) {
    if (placed[i].on_table) out.push_back(static_cast<int>(i));
  }
  return out;
}

std::optional<Candidate> ProposeTouching(const std::vector<Placed>& placed,
                                         const Body& body, Random& rng) {
  const std::vector<int> targets = OnTable(placed);
  if (targets.empty()) return std::nullopt;
  const Footprint& target =
      placed[targets[rng.UniformInt(0, static_cast<int>(targets.size()) - 1)]]
          .footprint;
  const float yaw = rng.Uniform(0.0f, 2.0f * kPi);
  const float angle = rng.Uniform(0.0f, 2.0f * kPi);
  const Vector2f dir(std::cos(angle), std::sin(angle));
  const Placed at_target = Pose(body, target.centre, 0.0f, yaw);
  const float distance =
      ContactDistance(target, at_target.footprint, target.centre, dir);
  return Candidate{
      Pose(body, target.centre + (distance + kContactGap) * dir, 0.0f, yaw),
      kContactGap / 2.0f, -1};
}

std::optional<Candidate> ProposeOccluding(const std::vector<Placed>& placed,
                                          const SceneSpec& spec,
                                          const Body& body, Random& rng) {
  const std::vector<int> targets = OnTable(placed);
  if (targets.empty()) return std::nullopt;
  const Footprint& target =
      placed[targets[rng.UniformInt(0, static_cast<int>(targets.size()) - 1)]]
          .footprint;
  const Vector2f eye = spec.camera_pose.translation().head<2>();
  if ((eye - target.centre).norm() < 1e-3f) return std::nullopt;
  const Vector2f dir = (eye - target.centre).normalized();
  const Vector2f side(-dir.y(), dir.x());
  const Vector2f start =
      target.centre + side * (target.BoundingRadius() * kOcclusionLateralShare *
                              rng.Uniform(-1.0f, 1.0f));
  const float yaw = rng.Uniform(0.0f, 2.0f * kPi);
  const Placed at_start = Pose(body, start, 0.0f, yaw);
  const float distance =
      ContactDistance(target, at_start.footprint, start, dir) +
      rng.Uniform(kOcclusionGapMin, kOcclusionGapMax);
  return Candidate{Pose(body, start + distance * dir, 0.0f, yaw),
                   kFreeClearance, -1};
}

// A box leaning over towards an object on the table, its foot beside it:
// tilted by 12-30 degrees about a horizontal axis, its top reaching over
// the gap to the other object.
std::optional<Candidate> ProposeLeaning(const std::vector<Placed>& placed,
                                        const Vector3f& rgb, Random& rng) {
  const std::vector<int> targets = OnTable(placed);
  if (targets.empty()) return std::nullopt;
  const Footprint& target =
      placed[targets[rng.UniformInt(0, static_cast<int>(targets.size()) - 1)]]
          .footprint;
  Body body;
  body.shape = Shape::kBox;
  body.rgb = rgb;
  body.half_extents = {rng.Uniform(0.008f, 0.025f), rng.Uniform(0.03f, 0.07f),
                       rng.Uniform(0.05f, 0.09f)};
  body.lean = rng.Uniform(kMinLean, kMaxLean);
  const float angle = rng.Uniform(0.0f, 2.0f * kPi);
  const Vector2f dir(std::cos(angle), std::sin(angle));  // target to box
  // A tilt about local y takes the top towards local +x: point local x at
  // the target (-dir from the box).
  const float yaw = angle + kPi;
  const Placed at_target = Pose(body, target.centre, 0.0f, yaw);
  const float distance =
      ContactDistance(target, at_target.footprint, target.centre, dir);
  Candidate c{
      Pose(body, target.centre + (distance + kContactGap) * dir, 0.0f, yaw),
      kContactGap / 2.0f, -1};
  c.placed.carries = true;  // nothing stacks on a leaning box
  return c;
}

// Whether every footprint point at both heights projects at least
// kViewMarginPx inside the image.
bool InView(const Footprint& f, const SceneSpec& spec) {
  const Eigen::Isometry3f world_to_camera = spec.camera_pose.inverse();
  const float r = f.BoundingRadius();
  const Intrinsics& k = spec.intrinsics;
  for (const float z : {f.z_min, f.z_max}) {
    for (const Vector2f& d : {Vector2f(0, 0), Vector2f(r, 0), Vector2f(-r, 0),
                              Vector2f(0, r), Vector2f(0, -r)}) {
      const Vector3f p = world_to_camera * Vector3f(f.centre.x() + d.x(),
                                                    f.centre.y() + d.y(), z);
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

bool Admissible(const Candidate& c, const std::vector<Placed>& placed,
                const SceneSpec& spec) {
  const Footprint& f = c.placed.footprint;
  const Vector2f reach = f.centre.cwiseAbs() + AabbHalf(f);
  if (reach.x() > spec.table_half_size.x() - kTableMargin ||
      reach.y() > spec.table_half_size.y() - kTableMargin) {
    return false;
  }
  if (!InView(f, spec)) return false;
  for (const Placed& p : placed) {
    if (Collides(f, p.footprint, c.clearance)) return false;
  }
  return true;
}

// Whether, with `c` added, every object keeps at least min_visible_fraction
// of its pixels seen alone (`alone`, extended with c's on success).
bool KeepsEveryObjectVisible(const Candidate& c,
                             const std::vector<Placed>& placed,
                             const SceneSpec& spec, float min_visible_fraction,
                             std::vector<int>* alone) {
  SceneSpec trial = spec;
  trial.objects = {c.placed.primitive};
  const int candidate_alone =
      ReducedObjectPixelCounts(trial, kVisibilityCastWidth)[0];
  trial.objects.clear();
  for (const Placed& p : placed) trial.objects.push_back(p.primitive);
  trial.objects.push_back(c.placed.primitive);
  const std::vector<int> counts =
      ReducedObjectPixelCounts(trial, kVisibilityCastWidth);
  for (size_t i = 0; i < counts.size(); ++i) {
    const int full = i < alone->size() ? (*alone)[i] : candidate_alone;
    if (counts[i] < kMinVisiblePixelsHalfRes ||
        counts[i] < min_visible_fraction * full) {
      return false;
    }
  }
  alone->push_back(candidate_alone);
  return true;
}

std::optional<Candidate> Propose(const std::vector<Placed>& placed,
                                 const SceneSpec& spec, const Vector2f& target,
                                 const RandomSceneOptions& options,
                                 Random& rng) {
  const Vector3f rgb =
      RandomAlbedo(spec.table_rgb, options.dark_object_probability, rng);
  const Body body =
      options.household ? RandomHouseholdBody(rgb, rng) : RandomBody(rgb, rng);
  float r = static_cast<float>(rng.Uniform());
  if (!placed.empty() && options.lean_probability > 0.0f) {
    if ((r -= options.lean_probability) < 0.0f) {
      return ProposeLeaning(placed, rgb, rng);
    }
  }
  if (!placed.empty()) {
    if ((r -= options.stack_probability) < 0.0f) {
      return ProposeStacked(placed, rgb, rng);
    }
    if ((r -= options.touch_probability) < 0.0f) {
      return ProposeTouching(placed, body, rng);
    }
    if ((r -= options.occlude_probability) < 0.0f) {
      return ProposeOccluding(placed, spec, body, rng);
    }
  }
  return ProposeFree(target, body, options.work_area_scale, rng);
}

}  // namespace

absl::Status Validate(const RandomSceneOptions& options) {
  if (options.min_objects < 0 || options.max_objects < options.min_objects ||
      options.max_objects > kMaxObjects) {
    return absl::InvalidArgumentError(
        "RandomSceneOptions.min_objects and max_objects must satisfy "
        "0 <= min_objects <= max_objects <= 20");
  }
  const float probabilities[] = {
      options.stack_probability, options.touch_probability,
      options.occlude_probability, options.dark_object_probability,
      options.min_visible_fraction};
  for (const float p : probabilities) {
    if (!(p >= 0.0f && p <= 1.0f)) {
      return absl::InvalidArgumentError(
          "RandomSceneOptions: stack_probability, touch_probability, "
          "occlude_probability, dark_object_probability and "
          "min_visible_fraction must be in [0, 1]");
    }
  }
  if (!(options.lean_probability >= 0.0f && options.lean_probability <= 1.0f)) {
    return absl::InvalidArgumentError(
        "RandomSceneOptions.lean_probability must be in [0, 1]");
  }
  if (options.stack_probability + options.touch_probability +
          options.occlude_probability + options.lean_probability >
      1.0f) {
    return absl::InvalidArgumentError(
        "RandomSceneOptions: stack_probability + touch_probability + "
        "occlude_probability + lean_probability must be <= 1");
  }
  if (!(options.work_area_scale > 0.0f && options.work_area_scale <= 1.0f)) {
    return absl::InvalidArgumentError(
        "RandomSceneOptions.work_area_scale must be in (0, 1]");
  }
  if (!(options.camera_height > 0.0f) || !(options.camera_distance >= 0.0f) ||
      !(options.camera_jitter >= 0.0f)) {
    return absl::InvalidArgumentError(
        "RandomSceneOptions.camera_height must be > 0, camera_distance and "
        "camera_jitter >= 0");
  }
  return absl::OkStatus();
}

Eigen::Isometry3f LookAt(const Vector3f& eye, const Vector3f& target) {
  FOVEA_CHECK((target - eye).norm() > 0.0f);
  const Vector3f forward = (target - eye).normalized();
  Vector3f right = forward.cross(Vector3f::UnitZ());
  Vector3f down;
  if (right.norm() < 1e-6f) {  // looking straight down or up
    down = -Vector3f::UnitY();
    right = down.cross(forward).normalized();
  } else {
    right.normalize();
    down = forward.cross(right);
  }
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear().col(0) = right;
  pose.linear().col(1) = down;
  pose.linear().col(2) = forward;
  pose.translation() = eye;
  return pose;
}

namespace {

// The objects of RandomSceneSpec / PlaceRandomObjects, from `rng`.
void PlaceObjects(const RandomSceneOptions& options, const Vector2f& target,
                  Random& rng, SceneSpec& spec) {
  const int wanted = rng.UniformInt(options.min_objects, options.max_objects);
  std::vector<Placed> placed;
  std::vector<int> alone;  // half-resolution pixels of each object alone
  for (int attempt = 0; static_cast<int>(placed.size()) < wanted &&
                        attempt < kAttemptsPerObject * wanted;
       ++attempt) {
    const std::optional<Candidate> c =
        Propose(placed, spec, target.head<2>(), options, rng);
    if (!c.has_value() || !Admissible(*c, placed, spec) ||
        !KeepsEveryObjectVisible(*c, placed, spec, options.min_visible_fraction,
                                 &alone)) {
      continue;
    }
    if (c->support >= 0) placed[c->support].carries = true;
    placed.push_back(c->placed);
  }
  for (const Placed& p : placed) spec.objects.push_back(p.primitive);
}

}  // namespace

SceneSpec RandomSceneSpec(uint64_t seed, const RandomSceneOptions& options) {
  FOVEA_CHECK(Validate(options).ok());
  Random rng(seed);
  SceneSpec spec;
  const float j = options.camera_jitter;
  const Vector3f eye(rng.Uniform(-j, j),
                     -options.camera_distance + rng.Uniform(-j, j),
                     options.camera_height + rng.Uniform(-j, j));
  const Vector3f target(rng.Uniform(-j, j), rng.Uniform(-j, j), 0.0f);
  spec.camera_pose = LookAt(eye, target);
  PlaceObjects(options, target.head<2>(), rng, spec);
  return spec;
}

void PlaceRandomObjects(uint64_t seed, const RandomSceneOptions& options,
                        const Eigen::Vector2f& target, SceneSpec& spec) {
  FOVEA_CHECK(Validate(options).ok());
  Random rng(seed);
  PlaceObjects(options, target, rng, spec);
}

}  // namespace fovea::synth
