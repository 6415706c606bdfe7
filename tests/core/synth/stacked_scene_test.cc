// Stacked piles: objects of several primitives under one label, bowls with
// flat floors, and piles where objects rest on each other.

#include "core/synth/stacked_scene.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/synth/raycast.h"
#include "core/synth/room.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {
namespace {

using Eigen::Vector3f;

constexpr int kSeeds = 6;

NoiseOptions NoNoise() {
  NoiseOptions noise;
  noise.enabled = false;
  return noise;
}

Primitive Box(const Vector3f& centre, const Vector3f& half) {
  Primitive p;
  p.shape = Shape::kBox;
  p.pose.translation() = centre;
  p.half_extents = half;
  return p;
}

// The piles of seeds 1..kSeeds (Kinect), generated once.
const std::vector<StackedPile>& Piles() {
  static const std::vector<StackedPile>* piles = [] {
    auto* out = new std::vector<StackedPile>;
    for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
      out->push_back(GenerateStackedPile(seed, RoomSensor::kKinectV1));
    }
    return out;
  }();
  return *piles;
}

// The primitives of object k: its own and its parts.
std::vector<Primitive> PrimitivesOf(const SceneSpec& spec, int k) {
  std::vector<Primitive> out = {spec.objects[k]};
  for (const ObjectPart& part : spec.object_parts) {
    if (part.object == k) out.push_back(part.primitive);
  }
  return out;
}

// `spec` holding object k (and its parts) alone, without the room.
SceneSpec Alone(const SceneSpec& spec, int k) {
  SceneSpec out = spec;
  out.background.clear();
  out.objects = {spec.objects[k]};
  out.object_parts.clear();
  for (const ObjectPart& part : spec.object_parts) {
    if (part.object == k) out.object_parts.push_back({part.primitive, 0});
  }
  return out;
}

// The lowest z of a box, or of a shape symmetric about its local z axis.
float LowestZ(const Primitive& p) {
  const Eigen::Matrix3f& r = p.pose.linear();
  const float z = p.pose.translation().z();
  if (p.shape == Shape::kBox) {
    return z - (std::abs(r(2, 0)) * p.half_extents.x() +
                std::abs(r(2, 1)) * p.half_extents.y() +
                std::abs(r(2, 2)) * p.half_extents.z());
  }
  const float axis_z = std::abs(r(2, 2));
  return z - (axis_z * p.half_extents.z() +
              p.radius * std::sqrt(std::max(0.0f, 1.0f - axis_z * axis_z)));
}

// The distance down from (x, y, z) to the nearest of `primitives`, or
// nullopt.
std::optional<float> DistanceDown(const std::vector<Primitive>& primitives,
                                  const Vector3f& from) {
  std::optional<float> best;
  for (const Primitive& p : primitives) {
    const std::optional<RayHit> hit =
        IntersectPrimitive(p, from, -Vector3f::UnitZ(), 0.0f, 1.0f);
    if (hit.has_value() && (!best.has_value() || hit->t < *best)) {
      best = hit->t;
    }
  }
  return best;
}

TEST(ObjectPartTest, PartsRenderWithTheirObjectsLabelAndCountInItsPixels) {
  SceneSpec spec;
  spec.camera_pose = LookAt(Vector3f(0, -0.6f, 0.7f), Vector3f::Zero());
  spec.objects = {Box(Vector3f(-0.1f, 0, 0.03f), Vector3f::Constant(0.03f)),
                  Box(Vector3f(0.1f, 0, 0.03f), Vector3f::Constant(0.03f))};
  const SynthScene one_part_each = RenderScene(spec, NoNoise(), 1);
  // A further box beside object 0, away from object 1.
  spec.object_parts = {
      {Box(Vector3f(-0.2f, 0, 0.03f), Vector3f::Constant(0.03f)), 0}};
  const SynthScene scene = RenderScene(spec, NoNoise(), 1);
  ASSERT_EQ(scene.objects.size(), 2u);
  const cv::Mat labels = scene.frame.labels;
  const int part_pixels = cv::countNonZero(labels == 20) -
                          cv::countNonZero(one_part_each.frame.labels == 20);
  EXPECT_GT(part_pixels, 500);
  EXPECT_EQ(scene.objects[0].visible_pixels, cv::countNonZero(labels == 20));
  EXPECT_EQ(scene.objects[1].visible_pixels,
            one_part_each.objects[1].visible_pixels);
  // No label of its own: only the table and the two objects' labels.
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      const int l = labels.at<int>(v, u);
      ASSERT_TRUE(l == 0 || l == 1 || l == 20 || l == 30) << l;
    }
  }
  spec.object_parts[0].object = 2;
  EXPECT_NE(Validate(spec).message().find("object_parts[0].object"),
            std::string::npos);
}

TEST(BowlFloorTest, AFlatFloorIsFlatOutToItsRadiusThenCurvesUp) {
  Primitive bowl;
  bowl.shape = Shape::kBowl;
  bowl.radius = 0.08f;
  bowl.half_extents = Vector3f(0.08f, 0.08f, 0.028f);
  bowl.thickness = 0.005f;
  bowl.floor_height = 0.012f;
  bowl.floor_radius = 0.045f;
  bowl.pose.translation() = Vector3f(0, 0, 0.028f);
  SceneSpec spec;
  spec.objects = {bowl};
  ASSERT_TRUE(Validate(spec).ok());
  // Down at 0, 2 and 4.4 cm from the axis: the floor, 12 mm up.
  for (const float x : {0.0f, 0.02f, 0.044f}) {
    const std::optional<float> d = DistanceDown({bowl}, Vector3f(x, 0, 1));
    ASSERT_TRUE(d.has_value());
    EXPECT_NEAR(1.0f - *d, 0.012f, 1e-5f) << x;
  }
  // Beyond the floor's edge the inside rises, below the rim (5.6 cm).
  const std::optional<float> d = DistanceDown({bowl}, Vector3f(0.06f, 0, 1));
  ASSERT_TRUE(d.has_value());
  EXPECT_GT(1.0f - *d, 0.015f);
  EXPECT_LT(1.0f - *d, 0.056f);
  // Without floor_radius the inside curves up right away.
  bowl.floor_radius = 0.0f;
  const std::optional<float> curved =
      DistanceDown({bowl}, Vector3f(0.044f, 0, 1));
  ASSERT_TRUE(curved.has_value());
  EXPECT_GT(1.0f - *curved, 0.02f);
  // A floor wider than the inside allows is refused.
  spec.objects[0].floor_radius = 0.07f;
  EXPECT_NE(Validate(spec).message().find("floor_radius"), std::string::npos);
}

TEST(StackedPileTest, SameSeedSameLabelsOtherSeedDiffers) {
  const StackedPile a = GenerateStackedPile(7, RoomSensor::kKinectV1);
  const StackedPile b = GenerateStackedPile(7, RoomSensor::kKinectV1);
  const StackedPile c = GenerateStackedPile(8, RoomSensor::kKinectV1);
  EXPECT_EQ(cv::countNonZero(a.scene.frame.labels != b.scene.frame.labels), 0);
  EXPECT_EQ(a.rests_on, b.rests_on);
  EXPECT_GT(cv::countNonZero(a.scene.frame.labels != c.scene.frame.labels),
            1000);
}

void ExpectEachRestsOnWhatItNames(const StackedPile& pile);

TEST(StackedPileTest, NameAndIntrinsicsFollowTheSensor) {
  const StackedPile kinect = GenerateStackedPile(3, RoomSensor::kKinectV1);
  const StackedPile stereo = GenerateStackedPile(3, RoomSensor::kActiveStereo);
  EXPECT_EQ(kinect.scene.frame.name, "stack-3");
  EXPECT_EQ(stereo.scene.frame.name, "stack-as-3");
  EXPECT_DOUBLE_EQ(kinect.scene.frame.frame.intrinsics.fx, 525.0);
  EXPECT_DOUBLE_EQ(stereo.scene.frame.frame.intrinsics.fx, 613.0);
  EXPECT_EQ(stereo.scene.frame.frame.color.cols, 640);
  EXPECT_EQ(stereo.scene.frame.frame.color.rows, 480);
  EXPECT_GE(stereo.kinds.size(), 8u);
  // Time of flight at its own 640x576, every object still in view.
  const StackedPile tof = GenerateStackedPile(3, RoomSensor::kTimeOfFlight);
  EXPECT_EQ(tof.scene.frame.name, "stack-tof-3");
  EXPECT_EQ(tof.scene.frame.frame.color.size(), cv::Size(640, 576));
  EXPECT_DOUBLE_EQ(tof.scene.frame.frame.intrinsics.fx, 504.0);
  EXPECT_GE(tof.kinds.size(), 8u);
  ExpectEachRestsOnWhatItNames(tof);
  EXPECT_EQ(GenerateStackedPile(3, RoomSensor::kTimeOfFlight,
                                AbovePileOptions(RoomSensor::kTimeOfFlight))
                .scene.frame.name,
            "stack-above-tof-3");
}

TEST(StackedPileTest, EveryPileHoldsEightToSixteenVisibleObjectsThreeStacked) {
  for (const StackedPile& pile : Piles()) {
    const std::string& name = pile.scene.frame.name;
    ASSERT_EQ(pile.kinds.size(), pile.scene.objects.size()) << name;
    ASSERT_EQ(pile.rests_on.size(), pile.scene.objects.size()) << name;
    EXPECT_GE(pile.scene.objects.size(), 8u) << name;
    EXPECT_LE(pile.scene.objects.size(), 16u) << name;
    EXPECT_GE(CountStacked(pile.rests_on), 3) << name;
    for (size_t k = 0; k < pile.scene.objects.size(); ++k) {
      EXPECT_GE(pile.scene.objects[k].visible_pixels, 150) << name << " " << k;
      EXPECT_LT(pile.rests_on[k], static_cast<int>(k)) << name;
    }
  }
}

TEST(StackedPileTest, EveryObjectKeepsThirtyPercentOfItsPixelsAlone) {
  // A render per object: the first four piles (about 50 objects) keep the
  // test to a second or two, and a few times that under the sanitizers.
  constexpr size_t kCheckedPiles = 4;
  for (size_t i = 0; i < kCheckedPiles && i < Piles().size(); ++i) {
    const StackedPile& pile = Piles()[i];
    SceneSpec bare = pile.spec;
    bare.background.clear();
    const SynthScene all = RenderScene(bare, NoNoise(), 1);
    for (size_t k = 0; k < all.objects.size(); ++k) {
      const SynthScene alone =
          RenderScene(Alone(pile.spec, static_cast<int>(k)), NoNoise(), 1);
      EXPECT_GE(all.objects[k].visible_pixels,
                0.3 * alone.objects[0].visible_pixels)
          << pile.scene.frame.name << " object " << k << " "
          << StackedKindName(pile.kinds[k]);
    }
  }
}

// Every object of `pile` rests on the table or on the object rests_on
// names.
void ExpectEachRestsOnWhatItNames(const StackedPile& pile) {
  for (size_t k = 0; k < pile.spec.objects.size(); ++k) {
    const Primitive& p = pile.spec.objects[k];
    const float bottom = LowestZ(p);
    const std::string what = pile.scene.frame.name + " object " +
                             std::to_string(k) + " " +
                             std::string(StackedKindName(pile.kinds[k]));
    if (pile.rests_on[k] < 0) {
      EXPECT_NEAR(bottom, 0.0f, 1e-4f) << what;
      continue;
    }
    // Straight below its middle, within 1 mm, is its support.
    const Vector3f centre = p.pose.translation();
    const std::optional<float> down =
        DistanceDown(PrimitivesOf(pile.spec, pile.rests_on[k]),
                     Vector3f(centre.x(), centre.y(), bottom + 0.001f));
    ASSERT_TRUE(down.has_value()) << what;
    EXPECT_NEAR(*down, 0.001f, 1e-3f) << what;
    EXPECT_GT(bottom, 0.0f) << what;
  }
}

TEST(StackedPileTest, EveryObjectRestsOnTheTableOrOnWhatRestsOnNames) {
  for (const StackedPile& pile : Piles()) ExpectEachRestsOnWhatItNames(pile);
}

TEST(StackedPileTest, ACupInABowlStandsOnTheBowlsFlatInnerFloor) {
  int cups_in_bowls = 0;
  for (const StackedPile& pile : Piles()) {
    for (size_t k = 0; k < pile.kinds.size(); ++k) {
      const int s = pile.rests_on[k];
      if (s < 0 || pile.kinds[s] != StackedKind::kBowl) continue;
      ASSERT_EQ(pile.kinds[k], StackedKind::kCup);
      ++cups_in_bowls;
      const Primitive& cup = pile.spec.objects[k];
      const Primitive& bowl = pile.spec.objects[s];
      const float cup_bottom =
          cup.pose.translation().z() - cup.half_extents.z();
      const float floor = bowl.pose.translation().z() - bowl.half_extents.z() +
                          std::max(bowl.thickness, bowl.floor_height);
      EXPECT_NEAR(cup_bottom, floor, 1e-3f) << pile.scene.frame.name;
      // The bowl is flat under the whole cup: below its bottom's rim, the
      // bowl's inside is at most 1 mm down and never above it (a curved
      // inside would rise into the cup: the ray, starting inside the bowl's
      // wall, would meet its outside far below).
      constexpr float kAbove = 0.002f;
      for (int i = 0; i < 8; ++i) {
        const float a = 6.2831853f * i / 8.0f;
        const Vector3f from =
            cup.pose.translation() +
            0.95f * cup.radius * Vector3f(std::cos(a), std::sin(a), 0.0f);
        const std::optional<float> down = DistanceDown(
            {bowl}, Vector3f(from.x(), from.y(), cup_bottom + kAbove));
        ASSERT_TRUE(down.has_value()) << pile.scene.frame.name;
        EXPECT_GE(*down, kAbove - 1e-4f) << pile.scene.frame.name;
        EXPECT_LE(*down, kAbove + 1e-3f) << pile.scene.frame.name;
      }
    }
  }
  EXPECT_GE(cups_in_bowls, 3);
}

TEST(StackedPileTest, PartsOfAnObjectCarryItsLabelAndMugHandlesAreSeen) {
  int multi_part_piles = 0;
  int handle_pixels = 0;
  for (const StackedPile& pile : Piles()) {
    const SceneSpec& spec = pile.spec;
    multi_part_piles += !spec.object_parts.empty();
    const RaycastImage ray = RaycastScene(spec);
    const int first_part =
        static_cast<int>(spec.objects.size() + spec.background.size()) + 1;
    const cv::Mat& labels = pile.scene.frame.labels;
    for (int v = 0; v < ray.hit.rows; ++v) {
      for (int u = 0; u < ray.hit.cols; ++u) {
        const int hit = ray.hit.at<int>(v, u);
        if (hit < first_part) continue;
        const int object = spec.object_parts[hit - first_part].object;
        const int label = labels.at<int>(v, u);
        if (label == 0) continue;  // the noise dropped its depth
        ASSERT_EQ(label, pile.scene.objects[object].label)
            << pile.scene.frame.name << " (" << u << ", " << v << ")";
        handle_pixels += pile.kinds[object] == StackedKind::kMug;
      }
    }
  }
  EXPECT_EQ(multi_part_piles, kSeeds);
  EXPECT_GT(handle_pixels, 200);
}

TEST(StackedPileTest, EveryKindOfStackingOccurs) {
  using K = StackedKind;
  auto count = [](K kind, std::optional<K> on) {
    int n = 0;
    for (const StackedPile& pile : Piles()) {
      for (size_t k = 0; k < pile.kinds.size(); ++k) {
        const int s = pile.rests_on[k];
        if (pile.kinds[k] != kind) continue;
        if (!on.has_value() ? s < 0 : (s >= 0 && pile.kinds[s] == *on)) ++n;
      }
    }
    return n;
  };
  EXPECT_GT(count(K::kBox, K::kBook), 0);
  EXPECT_GT(count(K::kBox, K::kBox), 0);
  EXPECT_GT(count(K::kBook, std::nullopt), 0);
  EXPECT_GT(count(K::kCup, K::kBowl), 0);
  EXPECT_GT(count(K::kBox, K::kOpenBox) + count(K::kCan, K::kOpenBox) +
                count(K::kCup, K::kOpenBox) + count(K::kMug, K::kOpenBox),
            0);
  EXPECT_GT(count(K::kMug, std::nullopt) + count(K::kMug, K::kBook), 0);
  EXPECT_GT(count(K::kPlate, std::nullopt) + count(K::kTablet, std::nullopt),
            0);
  int lying = 0;
  for (const StackedPile& pile : Piles()) {
    for (size_t k = 0; k < pile.kinds.size(); ++k) {
      const Primitive& p = pile.spec.objects[k];
      lying +=
          pile.kinds[k] == K::kCan && std::abs(p.pose.linear()(2, 2)) < 1e-3f;
    }
  }
  EXPECT_GT(lying, 0);
}

// The `stacked-above` piles: every kind occurs, a tower of three boxes
// too; the camera looks down steeply at the sensor's resolution; the piles
// keep the default piles' guarantees; and with the options at their
// defaults a seed gives the pile it gave before.
TEST(StackedPileTest, AbovePilesHoldEveryKindSeenFromAbove) {
  using K = StackedKind;
  std::map<K, int> kinds;
  int towers = 0;
  for (const RoomSensor sensor :
       {RoomSensor::kKinectV1, RoomSensor::kActiveStereo}) {
    const StackedPileOptions options = AbovePileOptions(sensor);
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      const StackedPile pile = GenerateStackedPile(seed, sensor, options);
      const std::string& name = pile.scene.frame.name;
      EXPECT_EQ(pile.scene.frame.frame.color.cols,
                sensor == RoomSensor::kKinectV1 ? 640 : 1280);
      EXPECT_EQ(pile.scene.frame.frame.color.rows,
                sensor == RoomSensor::kKinectV1 ? 480 : 720);
      EXPECT_EQ(name, (sensor == RoomSensor::kKinectV1 ? "stack-above-"
                                                       : "stack-above-as-") +
                          std::to_string(seed));
      // The optical axis within 35 degrees of straight down.
      const Vector3f axis = pile.spec.camera_pose.linear().col(2);
      EXPECT_LT(axis.z(), -std::cos(35.0f * 3.14159265f / 180.0f)) << name;
      EXPECT_GE(pile.scene.objects.size(), 8u) << name;
      EXPECT_GE(CountStacked(pile.rests_on), 3) << name;
      for (size_t k = 0; k < pile.kinds.size(); ++k) {
        ++kinds[pile.kinds[k]];
        EXPECT_GE(pile.scene.objects[k].visible_pixels, 40) << name << " " << k;
        const int below = pile.rests_on[k];
        if (pile.kinds[k] == K::kBox && below >= 0 &&
            pile.kinds[below] == K::kBox && pile.rests_on[below] >= 0 &&
            pile.kinds[pile.rests_on[below]] == K::kBox) {
          ++towers;
        }
      }
      ExpectEachRestsOnWhatItNames(pile);
    }
  }
  for (const K kind : {K::kDrill, K::kBanana, K::kPen, K::kPart}) {
    EXPECT_GT(kinds[kind], 0) << StackedKindName(kind);
  }
  EXPECT_GT(towers, 0);
  // Off by default: the default piles hold none of the new kinds.
  for (const StackedPile& pile : Piles()) {
    for (const K kind : pile.kinds) {
      EXPECT_NE(kind, K::kDrill);
      EXPECT_NE(kind, K::kBanana);
      EXPECT_NE(kind, K::kPen);
      EXPECT_NE(kind, K::kPart);
    }
  }
  StackedPileOptions bad;
  using ::testing::HasSubstr;
  bad.width = 100;
  EXPECT_THAT(Validate(bad).message(), HasSubstr("width"));
}

}  // namespace
}  // namespace fovea::synth
