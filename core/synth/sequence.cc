#include "core/synth/sequence.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"

namespace fovea::synth {
namespace {

constexpr float kPi = 3.14159265358979f;

RandomSceneOptions SequenceSceneOptions() {
  RandomSceneOptions o;
  o.min_objects = 3;
  o.max_objects = 7;
  o.household = true;
  o.stack_probability = 0.0f;  // any object may be taken away
  o.touch_probability = 0.3f;
  o.occlude_probability = 0.1f;
  return o;
}

// Where the camera's optical axis meets the table (z = 0).
Eigen::Vector3f LookedAt(const Eigen::Isometry3f& camera_to_world) {
  const Eigen::Vector3f eye = camera_to_world.translation();
  const Eigen::Vector3f axis = camera_to_world.linear().col(2);
  if (axis.z() >= -1e-3f) return {0.0f, 0.0f, 0.0f};
  return eye + axis * (-eye.z() / axis.z());
}

// `base` with only the objects marked present (parts follow their object);
// `ids` gets the present objects' indices in `base`.
SceneSpec WithObjects(const SceneSpec& base, const std::vector<bool>& present,
                      std::vector<int>& ids) {
  SceneSpec spec = base;
  spec.objects.clear();
  spec.object_parts.clear();
  ids.clear();
  std::vector<int> new_index(base.objects.size(), -1);
  for (size_t k = 0; k < base.objects.size(); ++k) {
    if (!present[k]) continue;
    new_index[k] = static_cast<int>(spec.objects.size());
    spec.objects.push_back(base.objects[k]);
    ids.push_back(static_cast<int>(k));
  }
  for (const ObjectPart& part : base.object_parts) {
    if (new_index[part.object] < 0) continue;
    ObjectPart moved = part;
    moved.object = new_index[part.object];
    spec.object_parts.push_back(moved);
  }
  return spec;
}

// How far object k reaches from its centre along the unit horizontal
// direction `d`: a box's support function, a round body's radius.
float Reach(const Primitive& object, const Eigen::Vector3f& d) {
  if (object.shape != Shape::kBox) return object.radius;
  const Eigen::Matrix3f r = object.pose.linear();
  float reach = 0.0f;
  for (int i = 0; i < 3; ++i) {
    reach += std::abs(d.dot(r.col(i))) * object.half_extents[i];
  }
  return reach;
}

// The object nearest to object k on the table (-1 when it is alone).
int Nearest(const SceneSpec& spec, int k) {
  int nearest = -1;
  float best = 0.0f;
  for (int j = 0; j < static_cast<int>(spec.objects.size()); ++j) {
    if (j == k) continue;
    Eigen::Vector3f d =
        spec.objects[j].pose.translation() - spec.objects[k].pose.translation();
    d.z() = 0.0f;
    if (nearest < 0 || d.norm() < best) {
      nearest = j;
      best = d.norm();
    }
  }
  return nearest;
}

// Moves object k (and its parts) by `delta` in the world.
void Translate(SceneSpec& spec, int k, const Eigen::Vector3f& delta) {
  spec.objects[k].pose.pretranslate(delta);
  for (ObjectPart& part : spec.object_parts) {
    if (part.object == k) part.primitive.pose.pretranslate(delta);
  }
}

}  // namespace

absl::Span<const NamedValue<SequenceKind>> SequenceKinds() {
  static constexpr NamedValue<SequenceKind> kTable[] = {
      {SequenceKind::kStatic, "static"},
      {SequenceKind::kDrift, "drift"},
      {SequenceKind::kApproach, "approach"},
      {SequenceKind::kPlace, "place"},
      {SequenceKind::kRemove, "remove"},
      {SequenceKind::kPush, "push"},
      {SequenceKind::kPickAndPlace, "pick-place"},
      {SequenceKind::kPushApart, "push-apart"},
  };
  return kTable;
}

Sequence GenerateSequence(SequenceKind kind, uint64_t seed, int frames) {
  FOVEA_CHECK(frames >= 2);
  SceneSpec base = RandomSceneSpec(seed, SequenceSceneOptions());
  const int n = static_cast<int>(base.objects.size());
  const Eigen::Isometry3f camera = base.camera_pose;
  const Eigen::Vector3f target = LookedAt(camera);
  std::mt19937_64 rng(seed * 7919 + static_cast<uint64_t>(kind));
  std::normal_distribution<float> shake(0.0f, 0.002f);
  std::uniform_real_distribution<float> phase(0.0f, 2.0f * kPi);
  const float phase_x = phase(rng);
  const float phase_y = phase(rng);
  std::uniform_int_distribution<int> pick(0, std::max(0, n - 1));
  const int moving = pick(rng);
  // The push's direction: away from the other objects' mean, on the table.
  Eigen::Vector3f away = Eigen::Vector3f::UnitX();
  if (n > 1) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (int k = 0; k < n; ++k) {
      if (k != moving) mean += base.objects[k].pose.translation();
    }
    mean /= static_cast<float>(n - 1);
    Eigen::Vector3f d = base.objects[moving].pose.translation() - mean;
    d.z() = 0.0f;
    if (d.norm() > 1e-3f) away = d.normalized();
  }

  // The push-apart's pair: `moving` and its nearest neighbour, moved to
  // stand against it, 2 mm apart, on its side (`side`, from `moving`); both
  // are swept along `away`, then `moving` is pulled back from `side`.
  int partner = -1;
  Eigen::Vector3f side = Eigen::Vector3f::UnitX();
  if (kind == SequenceKind::kPushApart && n > 1) {
    partner = Nearest(base, moving);
    side = base.objects[partner].pose.translation() -
           base.objects[moving].pose.translation();
    side.z() = 0.0f;
    side = side.norm() > 1e-3f ? side.normalized() : Eigen::Vector3f::UnitX();
    const Eigen::Vector3f at =
        base.objects[moving].pose.translation() +
        side * (Reach(base.objects[moving], side) +
                Reach(base.objects[partner], side) + 0.002f);
    Eigen::Vector3f delta = at - base.objects[partner].pose.translation();
    delta.z() = 0.0f;
    Translate(base, partner, delta);
  }

  Sequence sequence;
  sequence.name =
      absl::StrCat(AbslView(NameOf(SequenceKinds(), kind)), "-", seed);
  for (int t = 0; t < frames; ++t) {
    const float s = static_cast<float>(t) / static_cast<float>(frames - 1);
    SceneSpec moved = base;
    std::vector<bool> present(n, true);
    switch (kind) {
      case SequenceKind::kStatic:
        break;
      case SequenceKind::kDrift: {
        const Eigen::Vector3f offset(
            0.03f * std::sin(2.0f * kPi * s + phase_x) + shake(rng),
            0.02f * std::sin(2.0f * kPi * s + phase_y) + shake(rng),
            0.01f * std::sin(4.0f * kPi * s) + shake(rng));
        const Eigen::Vector3f eye = camera.translation() + offset;
        moved.camera_pose = LookAt(eye, target + 0.5f * offset);
        break;
      }
      case SequenceKind::kApproach: {
        const Eigen::Vector3f eye =
            target + (camera.translation() - target) * (1.0f - 0.4f * s);
        moved.camera_pose = LookAt(eye, target);
        break;
      }
      case SequenceKind::kPlace:
      case SequenceKind::kRemove: {
        // Object k is present from frame (k + 1) * frames / (n + 1) on when
        // placing; taken away at that frame when removing.
        for (int k = 0; k < n; ++k) {
          const int at = (k + 1) * frames / (n + 1);
          present[k] = kind == SequenceKind::kPlace ? t >= at : t < at;
        }
        present[0] = true;  // one object stays throughout
        break;
      }
      case SequenceKind::kPush:
        if (n > 0) Translate(moved, moving, away * (0.01f * t));
        break;
      case SequenceKind::kPickAndPlace: {
        // Away for the middle third, then back 12 cm further along `away`.
        const int lift = frames / 3;
        const int put = 2 * frames / 3;
        if (n > 0 && t >= lift && t < put) present[moving] = false;
        if (n > 0 && t >= put) Translate(moved, moving, away * 0.12f);
        break;
      }
      case SequenceKind::kPushApart: {
        if (partner < 0) break;
        const int half = frames / 2;
        const float swept = 0.03f * static_cast<float>(std::min(t, half));
        const float pulled = 0.03f * static_cast<float>(std::max(0, t - half));
        Translate(moved, moving, away * swept - side * pulled);
        Translate(moved, partner, away * swept);
        break;
      }
    }
    SequenceFrame frame;
    const SceneSpec spec = WithObjects(moved, present, frame.object_ids);
    frame.camera_to_world = spec.camera_pose;
    SynthScene scene =
        RenderScene(spec, IndependentKinectV1Noise(), seed * 1000 + t);
    frame.frame = std::move(scene.frame);
    frame.frame.name = absl::StrCat(sequence.name, "-", t);
    sequence.frames.push_back(std::move(frame));
  }
  return sequence;
}

}  // namespace fovea::synth
