// RandomRoomSpec: a support table with clutter in a room.
//
// World frame as in synth_scene.h: the support table's top is z = 0, +z up,
// the table spans |x| <= hx, |y| <= hy. The floor is z = -H. The camera
// stands on the -y side of the table (within +-60 degrees of it), looks at
// a point on the table from a robot's head height, slightly rolled. The
// room is built around that: walls behind and beside, an optional second
// table beyond a gap, furniture and boxes on the floor kept out of the
// camera's line of sight to the table.

#include "core/synth/room.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/name_table.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/synth/random.h"
#include "core/synth/random_bodies.h"
#include "core/synth/textures.h"

namespace fovea::synth {
namespace {

constexpr NamedValue<RoomSensor> kRoomSensors[] = {
    {RoomSensor::kKinectV1, "kinect_v1"},
    {RoomSensor::kActiveStereo, "active_stereo"},
    {RoomSensor::kTimeOfFlight, "time_of_flight"},
};

using Eigen::Vector2f;
using Eigen::Vector3f;

constexpr float kPi = 3.14159265358979f;
// Stream ids mixed into the seed so that the room, the clutter and the
// noise draw from unrelated streams.
constexpr uint64_t kClutterStream = 0x636c75747465ULL;  // "clutte"

// Support table, metres.
constexpr float kTableHalfXMin = 0.30f, kTableHalfXMax = 0.75f;
constexpr float kTableHalfYMin = 0.22f, kTableHalfYMax = 0.45f;
constexpr float kTableHeightMin = 0.40f, kTableHeightMax = 0.78f;
constexpr float kTopThicknessMin = 0.02f, kTopThicknessMax = 0.045f;
constexpr float kLegHalfMin = 0.018f, kLegHalfMax = 0.03f;
constexpr float kLegInsetMin = 0.03f, kLegInsetMax = 0.08f;
// Below the table's top rectangle, so the rectangle is what a ray sees.
constexpr float kTopRecess = 0.0005f;

// Camera: bearing from the table's -y side, distance back from the near
// edge, height above the table top, roll.
constexpr float kBearingMax = kPi / 3.0f;
constexpr float kBackMin = 0.05f, kBackMax = 0.6f;
constexpr float kMinCameraAboveTable = 0.3f;
constexpr float kRollMax = 5.0f * kPi / 180.0f;

// Walls: probability behind / each side, distance from the table centre,
// height.
constexpr float kBackWallProbability = 0.8f;
constexpr float kSideWallProbability = 0.4f;
constexpr float kWallDistanceMax = 4.0f;
constexpr float kWallHalfThickness = 0.025f;
constexpr float kWallHalfHeight = 1.3f;
constexpr float kWallHalfLength = 8.0f;

// Second table: gap to the support table's edge, size, other heights.
constexpr float kGapMin = 0.12f, kGapMax = 1.2f;
constexpr float kOtherHeightMin = -0.25f, kOtherHeightMax = 0.15f;
constexpr float kOtherHeightMinDifference = 0.04f;
constexpr int kOtherTableObjectsMax = 4;

// Furniture on the floor.
constexpr float kKeepClearOfTable = 0.25f;   // metres from the table's edge
constexpr float kKeepClearOfCamera = 0.5f;   // metres from the eye
constexpr float kFurnitureRadiusMax = 3.0f;  // from the table centre
constexpr int kPlacementAttempts = 30;

Vector3f Rgb(float r, float g, float b) { return {r, g, b}; }

Primitive Box(const Vector3f& centre, const Vector3f& half, float yaw,
              const Vector3f& rgb, Texture texture) {
  Primitive p;
  p.shape = Shape::kBox;
  p.pose = Eigen::Isometry3f::Identity();
  p.pose.linear() =
      Eigen::AngleAxisf(yaw, Vector3f::UnitZ()).toRotationMatrix();
  p.pose.translation() = centre;
  p.half_extents = half;
  p.rgb = rgb;
  p.texture = texture;
  return p;
}

// A random muted colour (furniture, walls, floors), value in [lo, hi].
Vector3f MutedRgb(Random& rng, float lo, float hi) {
  const float v = rng.Uniform(lo, hi);
  const Vector3f tint(rng.Uniform(-0.06f, 0.06f), rng.Uniform(-0.06f, 0.06f),
                      rng.Uniform(-0.06f, 0.06f));
  return (Vector3f::Constant(v) + tint).cwiseMax(0.02f).cwiseMin(1.0f);
}

// A saturated colour for things standing on other tables and the floor.
Vector3f BrightRgb(Random& rng) {
  const float h = rng.Uniform(0.0f, 1.0f);
  const float s = rng.Uniform(0.4f, 0.9f), v = rng.Uniform(0.45f, 0.95f);
  return HsvToRgb(h, s, v);
}

// A table's top (label `top_label`) and four legs standing on the floor at
// z = -floor_depth below the support top. Its top face is at z = top_z.
void AddTable(const Vector2f& centre, const Vector2f& half, float yaw,
              float top_z, float floor_depth, float thickness,
              const Vector3f& rgb, Texture texture, int top_label, Random& rng,
              std::vector<BackgroundPart>& parts) {
  parts.push_back(
      {Box(Vector3f(centre.x(), centre.y(), top_z - thickness / 2),
           Vector3f(half.x(), half.y(), thickness / 2), yaw, rgb, texture),
       top_label});
  const float leg_half = rng.Uniform(kLegHalfMin, kLegHalfMax);
  const float inset = rng.Uniform(kLegInsetMin, kLegInsetMax);
  const float leg_top = top_z - thickness;
  const float leg_half_height = (leg_top + floor_depth) / 2;
  if (!(leg_half_height > 0.01f)) return;
  const Vector3f leg_rgb =
      rng.Bernoulli(0.5) ? rgb * 0.8f : MutedRgb(rng, 0.2f, 0.6f);
  const Eigen::Rotation2Df turn(yaw);
  for (const float sx : {-1.0f, 1.0f}) {
    for (const float sy : {-1.0f, 1.0f}) {
      const Vector2f local(sx * (half.x() - inset), sy * (half.y() - inset));
      const Vector2f xy = centre + turn * local;
      parts.push_back({Box(Vector3f(xy.x(), xy.y(), leg_top - leg_half_height),
                           Vector3f(leg_half, leg_half, leg_half_height), yaw,
                           leg_rgb, Texture::kFlat),
                       kFurnitureLabel});
    }
  }
}

// Oriented rectangles (centre, half size, yaw) in the floor plan.
struct Rect {
  Vector2f centre;
  Vector2f half;
  float yaw = 0.0f;
};

// Whether two oriented rectangles grown by `margin` overlap (separating
// axes).
bool Overlap(const Rect& a, const Rect& b, float margin) {
  const Eigen::Rotation2Df ra(a.yaw), rb(b.yaw);
  const Vector2f axes[4] = {ra * Vector2f::UnitX(), ra * Vector2f::UnitY(),
                            rb * Vector2f::UnitX(), rb * Vector2f::UnitY()};
  const Vector2f d = b.centre - a.centre;
  for (const Vector2f& axis : axes) {
    const float reach_a = std::abs((ra * Vector2f(a.half.x(), 0)).dot(axis)) +
                          std::abs((ra * Vector2f(0, a.half.y())).dot(axis));
    const float reach_b = std::abs((rb * Vector2f(b.half.x(), 0)).dot(axis)) +
                          std::abs((rb * Vector2f(0, b.half.y())).dot(axis));
    if (std::abs(d.dot(axis)) > reach_a + reach_b + margin) return false;
  }
  return true;
}

// Whether the floor-plan rectangle hides part of the support table from
// the eye: it meets the triangle eye - table near corners, approximated by
// the segment from the eye to the table centre and to its corners.
bool BlocksView(const Rect& r, const Vector2f& eye, const Rect& table) {
  const Eigen::Rotation2Df rt(table.yaw);
  const Vector2f targets[5] = {
      table.centre,
      table.centre + rt * Vector2f(table.half.x(), table.half.y()),
      table.centre + rt * Vector2f(-table.half.x(), table.half.y()),
      table.centre + rt * Vector2f(table.half.x(), -table.half.y()),
      table.centre + rt * Vector2f(-table.half.x(), -table.half.y())};
  for (const Vector2f& t : targets) {
    for (int i = 1; i < 10; ++i) {
      const Vector2f p = eye + (t - eye) * (i / 10.0f);
      const Rect dot{p, Vector2f::Constant(0.01f), 0.0f};
      if (Overlap(r, dot, 0.05f)) return true;
    }
  }
  return false;
}

// Distance from the table centre to its edge along the unit direction.
float EdgeDistance(const Vector2f& half, const Vector2f& dir) {
  const float ax =
      std::abs(dir.x()) > 1e-6f ? half.x() / std::abs(dir.x()) : 1e9f;
  const float ay =
      std::abs(dir.y()) > 1e-6f ? half.y() / std::abs(dir.y()) : 1e9f;
  return std::min(ax, ay);
}

}  // namespace

std::string_view RoomSensorName(RoomSensor sensor) {
  return NameOf<RoomSensor>(kRoomSensors, sensor);
}

std::string_view RoomSensorTag(RoomSensor sensor) {
  switch (sensor) {
    case RoomSensor::kKinectV1:
      return "";
    case RoomSensor::kActiveStereo:
      return "as-";
    case RoomSensor::kTimeOfFlight:
      return "tof-";
  }
  return "";
}

absl::StatusOr<RoomSensor> ParseRoomSensor(std::string_view text) {
  return ParseNamed<RoomSensor>(kRoomSensors, "room sensor", "kind", text);
}

absl::Status Validate(const RoomOptions& options) {
  if (options.width < 160 || options.width > 1920 || options.height < 120 ||
      options.height > 1080) {
    return absl::InvalidArgumentError(
        absl::StrCat("RoomOptions.width x height must be within 160x120 and "
                     "1920x1080, got ",
                     options.width, "x", options.height));
  }
  FOVEA_RETURN_IF_ERROR(Validate(options.clutter));
  for (const float p :
       {options.second_table_probability, options.same_height_probability}) {
    if (!(p >= 0.0f && p <= 1.0f)) {
      return absl::InvalidArgumentError(
          "RoomOptions.second_table_probability and same_height_probability "
          "must be in [0, 1]");
    }
  }
  if (options.max_cabinets < 0 || options.max_chairs < 0 ||
      options.max_floor_boxes < 0) {
    return absl::InvalidArgumentError(
        "RoomOptions.max_cabinets, max_chairs and max_floor_boxes must be >= "
        "0");
  }
  if (!(options.min_camera_height > 0.0f) ||
      !(options.max_camera_height >= options.min_camera_height)) {
    return absl::InvalidArgumentError(
        "RoomOptions.min_camera_height must be > 0 and <= max_camera_height");
  }
  return absl::OkStatus();
}

NoiseOptions RoomNoise(RoomSensor sensor) {
  switch (sensor) {
    case RoomSensor::kKinectV1:
      return KinectV1Noise();
    case RoomSensor::kActiveStereo:
      return ActiveStereoNoise();
    case RoomSensor::kTimeOfFlight:
      return TimeOfFlightNoise();
  }
  return KinectV1Noise();
}

cv::Size SensorFrameSize(RoomSensor sensor) {
  return sensor == RoomSensor::kTimeOfFlight ? cv::Size(640, 576)
                                             : cv::Size(640, 480);
}

Intrinsics SensorIntrinsics(RoomSensor sensor, int width, int height) {
  Intrinsics k;
  const double w = width, h = height;
  if (sensor == RoomSensor::kKinectV1) {
    k.fx = k.fy = 525.0 * w / 640.0;
    k.cx = (w - 1.0) / 2.0;
    k.cy = (h - 1.0) / 2.0;
    return k;
  }
  if (sensor == RoomSensor::kTimeOfFlight) {
    // Azure Kinect NFOV unbinned: 75 x 65 degrees at 640x576.
    k.fx = k.fy = 504.0 * w / 640.0;
    k.cx = w / 2.0 + 1.0 * w / 640.0;
    k.cy = h / 2.0 + 4.0 * h / 576.0;
    return k;
  }
  const bool wide = w / h > 1.55;  // 16:9 rather than 4:3
  k.fx = k.fy = wide ? 920.0 * w / 1280.0 : 613.0 * w / 640.0;
  k.cx = w / 2.0 + 2.5 * w / 640.0;
  k.cy = h / 2.0 + 8.0 * h / 480.0;
  return k;
}

SceneSpec RandomRoomSpec(uint64_t seed, const RoomOptions& options) {
  FOVEA_CHECK(Validate(options).ok());
  Random rng(seed);
  SceneSpec spec;
  spec.width = options.width;
  spec.height = options.height;
  spec.intrinsics =
      SensorIntrinsics(options.sensor, options.width, options.height);

  // The support table.
  const Vector2f half(rng.Uniform(kTableHalfXMin, kTableHalfXMax),
                      rng.Uniform(kTableHalfYMin, kTableHalfYMax));
  const float table_height = rng.Uniform(kTableHeightMin, kTableHeightMax);
  const float thickness = rng.Uniform(kTopThicknessMin, kTopThicknessMax);
  spec.table_half_size = half;
  const bool wooden = rng.Bernoulli(0.7);
  spec.table_rgb =
      wooden ? Rgb(rng.Uniform(0.5f, 0.75f), rng.Uniform(0.35f, 0.55f),
                   rng.Uniform(0.2f, 0.35f))
             : MutedRgb(rng, 0.55f, 0.9f);
  spec.table_texture = wooden ? Texture::kWood : Texture::kPaint;
  std::vector<BackgroundPart>& parts = spec.background;
  AddTable(Vector2f::Zero(), half, 0.0f, -kTopRecess, table_height - kTopRecess,
           thickness, spec.table_rgb, spec.table_texture, kSupportTableLabel,
           rng, parts);
  const Rect table_rect{Vector2f::Zero(), half, 0.0f};

  // The camera.
  const float bearing = rng.Uniform(-kBearingMax, kBearingMax);
  const Vector2f dir(std::sin(bearing), -std::cos(bearing));  // to the eye
  const float back = rng.Uniform(kBackMin, kBackMax);
  const float eye_distance = EdgeDistance(half, dir) + back;
  const float camera_height = std::max(
      rng.Uniform(options.min_camera_height, options.max_camera_height),
      table_height + kMinCameraAboveTable);
  const Vector3f eye(dir.x() * eye_distance, dir.y() * eye_distance,
                     camera_height - table_height);
  const Vector2f target_xy(rng.Uniform(-0.3f, 0.3f) * half.x(),
                           rng.Uniform(-0.3f, 0.3f) * half.y());
  spec.camera_pose = LookAt(eye, Vector3f(target_xy.x(), target_xy.y(), 0.0f));
  spec.camera_pose.linear() =
      spec.camera_pose.linear() *
      Eigen::AngleAxisf(rng.Uniform(-kRollMax, kRollMax), Vector3f::UnitZ())
          .toRotationMatrix();

  // The clutter on it (no background yet: PlaceRandomObjects ignores it
  // anyway, and the walls are not known).
  PlaceRandomObjects(seed ^ kClutterStream, options.clutter, target_xy, spec);

  // The floor.
  const float floor_z = -table_height;
  const int floor_kind = rng.UniformInt(0, 2);
  const Vector3f floor_rgb =
      floor_kind == 0 ? Rgb(rng.Uniform(0.2f, 0.35f), rng.Uniform(0.25f, 0.4f),
                            rng.Uniform(0.3f, 0.5f))
                      : MutedRgb(rng, 0.25f, 0.6f);
  parts.push_back(
      {Box(Vector3f(0, 0, floor_z - 0.01f),
           Vector3f(kWallHalfLength, kWallHalfLength, 0.01f), 0.0f, floor_rgb,
           floor_kind == 2 ? Texture::kWood : Texture::kCarpet),
       kFloorLabel});

  // Walls, beyond everything else; the side walls leave room for the eye.
  const Vector2f side(-dir.y(), dir.x());
  const float far_edge = EdgeDistance(half, -dir);
  std::vector<Rect> taken = {table_rect};
  const Vector3f wall_rgb = MutedRgb(rng, 0.55f, 0.9f);
  const float back_wall =
      rng.Uniform(std::max(far_edge + 0.9f, 1.2f), kWallDistanceMax);
  float side_limit = kWallDistanceMax;
  if (rng.Bernoulli(kBackWallProbability)) {
    const Vector2f c = -dir * (back_wall + kWallHalfThickness);
    parts.push_back(
        {Box(Vector3f(c.x(), c.y(), floor_z + kWallHalfHeight),
             Vector3f(kWallHalfLength, kWallHalfThickness, kWallHalfHeight),
             bearing, wall_rgb, Texture::kPaint),
         kWallLabel});
  }
  for (const float s : {-1.0f, 1.0f}) {
    if (!rng.Bernoulli(kSideWallProbability)) continue;
    const float d =
        rng.Uniform(EdgeDistance(half, side) + 0.8f, kWallDistanceMax);
    side_limit = std::min(side_limit, d);
    const Vector2f c = side * (s * (d + kWallHalfThickness));
    parts.push_back(
        {Box(Vector3f(c.x(), c.y(), floor_z + kWallHalfHeight),
             Vector3f(kWallHalfThickness, kWallHalfLength, kWallHalfHeight),
             bearing, wall_rgb * 0.95f, Texture::kPaint),
         kWallLabel});
  }
  // Everything else keeps inside this radius of the table centre.
  const float room_radius =
      std::min({back_wall - 0.2f, side_limit - 0.2f, kFurnitureRadiusMax});

  // A second table beyond a gap, behind or beside the support table.
  if (rng.Bernoulli(options.second_table_probability)) {
    const Vector2f other_half(rng.Uniform(kTableHalfXMin, kTableHalfXMax),
                              rng.Uniform(kTableHalfYMin, kTableHalfYMax));
    const float gap = rng.Uniform(kGapMin, kGapMax);
    Vector2f centre;
    const int where = rng.UniformInt(0, 2);  // behind, left, right
    if (where == 0) {
      centre = {rng.Uniform(-0.3f, 0.3f), half.y() + gap + other_half.y()};
    } else {
      const float s = where == 1 ? -1.0f : 1.0f;
      centre = {s * (half.x() + gap + other_half.x()), rng.Uniform(0.0f, 0.4f)};
    }
    float top_z = 0.0f;
    if (!rng.Bernoulli(options.same_height_probability)) {
      do {
        top_z = rng.Uniform(kOtherHeightMin, kOtherHeightMax);
      } while (std::abs(top_z) < kOtherHeightMinDifference);
    }
    const Rect other{centre, other_half, 0.0f};
    const Vector2f eye_xy = eye.head<2>();
    if (centre.norm() + other_half.norm() < room_radius + 0.5f &&
        !BlocksView(other, eye_xy, table_rect) &&
        (eye_xy - centre).norm() > other_half.norm() + kKeepClearOfCamera) {
      const Vector3f rgb =
          rng.Bernoulli(0.5) ? spec.table_rgb : MutedRgb(rng, 0.4f, 0.85f);
      AddTable(centre, other_half, 0.0f, top_z - kTopRecess,
               table_height + top_z - kTopRecess, thickness, rgb,
               rng.Bernoulli(0.5) ? Texture::kWood : Texture::kPaint,
               kOtherTableLabel, rng, parts);
      taken.push_back(other);
      // Its objects: boxes and standing cylinders, spaced apart.
      const int n = rng.UniformInt(1, kOtherTableObjectsMax);
      std::vector<Rect> on_it;
      for (int i = 0, attempts = 0; i < n && attempts < kPlacementAttempts;
           ++attempts) {
        const Vector2f h(rng.Uniform(0.02f, 0.08f), rng.Uniform(0.02f, 0.08f));
        const Vector2f c =
            centre +
            Vector2f(
                rng.Uniform(-1.0f, 1.0f) * (other_half.x() - h.x() - 0.02f),
                rng.Uniform(-1.0f, 1.0f) * (other_half.y() - h.y() - 0.02f));
        const Rect r{c, h, rng.Uniform(0.0f, kPi)};
        bool free = true;
        for (const Rect& q : on_it) free = free && !Overlap(r, q, 0.02f);
        if (!free) continue;
        const float hz = rng.Uniform(0.02f, 0.1f);
        Primitive p;
        if (rng.Bernoulli(0.5)) {
          p = Box(Vector3f(c.x(), c.y(), top_z + hz),
                  Vector3f(h.x(), h.y(), hz), r.yaw, BrightRgb(rng),
                  Texture::kFlat);
        } else {
          p.shape = Shape::kCylinder;
          p.radius = std::min(h.x(), h.y());
          p.half_extents = Vector3f(p.radius, p.radius, hz);
          p.pose = Eigen::Isometry3f::Identity();
          p.pose.translation() = Vector3f(c.x(), c.y(), top_z + hz);
          p.rgb = BrightRgb(rng);
        }
        parts.push_back({p, kOtherObjectLabel});
        on_it.push_back(r);
        ++i;
      }
    }
  }

  // Furniture and boxes on the floor, out of the way of the camera's view
  // of the table.
  const Vector2f eye_xy = eye.head<2>();
  auto place_on_floor = [&](const Vector2f& half_size) -> std::optional<Rect> {
    for (int attempt = 0; attempt < kPlacementAttempts; ++attempt) {
      const float angle = rng.Uniform(0.0f, 2.0f * kPi);
      const float radius = rng.Uniform(0.3f, room_radius);
      const Rect r{Vector2f(std::cos(angle), std::sin(angle)) * radius,
                   half_size, rng.Uniform(0.0f, kPi)};
      if ((r.centre - eye_xy).norm() < half_size.norm() + kKeepClearOfCamera)
        continue;
      if (r.centre.norm() + half_size.norm() > room_radius) continue;
      if (BlocksView(r, eye_xy, table_rect)) continue;
      bool free = true;
      for (const Rect& q : taken)
        free = free && !Overlap(r, q, kKeepClearOfTable);
      if (!free) continue;
      taken.push_back(r);
      return r;
    }
    return std::nullopt;
  };
  const int cabinets = rng.UniformInt(0, options.max_cabinets);
  for (int i = 0; i < cabinets; ++i) {
    const Vector3f h(rng.Uniform(0.2f, 0.45f), rng.Uniform(0.2f, 0.3f),
                     rng.Uniform(0.2f, 0.5f));
    if (const std::optional<Rect> r = place_on_floor(h.head<2>())) {
      parts.push_back(
          {Box(Vector3f(r->centre.x(), r->centre.y(), floor_z + h.z()), h,
               r->yaw, MutedRgb(rng, 0.2f, 0.8f), Texture::kPaint),
           kFurnitureLabel});
    }
  }
  const int chairs = rng.UniformInt(0, options.max_chairs);
  for (int i = 0; i < chairs; ++i) {
    const float seat = rng.Uniform(0.2f, 0.24f);
    const std::optional<Rect> r = place_on_floor(Vector2f(seat, seat));
    if (!r) continue;
    const float seat_z = floor_z + rng.Uniform(0.42f, 0.5f);
    const Vector3f rgb = MutedRgb(rng, 0.1f, 0.6f);
    const Eigen::Rotation2Df turn(r->yaw);
    parts.push_back(
        {Box(Vector3f(r->centre.x(), r->centre.y(), seat_z - 0.025f),
             Vector3f(seat, seat, 0.025f), r->yaw, rgb, Texture::kFlat),
         kFurnitureLabel});
    const Vector2f back_xy = r->centre + turn * Vector2f(0.0f, seat - 0.02f);
    parts.push_back(
        {Box(Vector3f(back_xy.x(), back_xy.y(), seat_z + 0.22f),
             Vector3f(seat, 0.02f, 0.22f), r->yaw, rgb, Texture::kFlat),
         kFurnitureLabel});
    for (const float sx : {-1.0f, 1.0f}) {
      for (const float sy : {-1.0f, 1.0f}) {
        const Vector2f xy = r->centre + turn * Vector2f(sx * (seat - 0.03f),
                                                        sy * (seat - 0.03f));
        const float half_height = (seat_z - 0.05f - floor_z) / 2;
        parts.push_back({Box(Vector3f(xy.x(), xy.y(), floor_z + half_height),
                             Vector3f(0.015f, 0.015f, half_height), r->yaw,
                             rgb * 0.7f, Texture::kFlat),
                         kFurnitureLabel});
      }
    }
  }
  const int boxes = rng.UniformInt(0, options.max_floor_boxes);
  for (int i = 0; i < boxes; ++i) {
    const Vector3f h(rng.Uniform(0.05f, 0.2f), rng.Uniform(0.05f, 0.2f),
                     rng.Uniform(0.04f, 0.2f));
    if (const std::optional<Rect> r = place_on_floor(h.head<2>())) {
      parts.push_back(
          {Box(Vector3f(r->centre.x(), r->centre.y(), floor_z + h.z()), h,
               r->yaw, BrightRgb(rng), Texture::kFlat),
           kOtherObjectLabel});
    }
  }
  return spec;
}

SynthScene GenerateRoom(uint64_t seed, const RoomOptions& options) {
  SceneSpec spec = RandomRoomSpec(seed, options);
  AddPrints(seed, kPrintedObjectShare, spec);
  SynthScene scene = RenderScene(spec, RoomNoise(options.sensor), seed);
  scene.frame.name =
      absl::StrCat("room-", AbslView(RoomSensorName(options.sensor)), "-",
                   options.width, "x", options.height, "-", seed);
  return scene;
}

}  // namespace fovea::synth
