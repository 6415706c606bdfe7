#ifndef FOVEA_CORE_SYNTH_STACKED_SCENE_H_
#define FOVEA_CORE_SYNTH_STACKED_SCENE_H_

#include <cstdint>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/synth/room.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// Stacked table-top piles: 8-16 household objects in a compact pile where
// many rest on other objects, the case object segmentation finds hardest.
// World frame as in synth_scene.h (table top z = 0, +z up, metres).
//
// Kinds of stacking, mixed within each pile: books on the table and on
// books, boxes on books and on boxes, cups standing on a bowl's flat inner
// floor, objects inside an open box (a bottom and four walls, one object),
// cans and bottles lying on their side, mugs (a cup with a "C" handle of
// three small boxes, one object), and thin objects (plates, tablets) lying
// flat. Books are one object of four primitives too: the cover and three
// strips of pages. Objects of several primitives keep one label: the first
// primitive is SceneSpec::objects[k], the others SceneSpec::object_parts of
// object k.
//
// The scene around the pile: a wood-textured table (label 1, its edge too),
// a painted wall behind it (label 3) and the floor (label 2).

enum class StackedKind {
  kBook,     // 15-25 cm wide, 2-5 cm thick, lying flat; cover + 3 page strips
  kBox,      // 5-14 cm across, 4-12 cm tall
  kCup,      // 5-8 cm across, 8-11 cm tall (Shape::kCup)
  kMug,      // a cup and a handle of three boxes
  kBowl,     // 13-18 cm across, with a flat inner floor (floor_radius > 0)
  kOpenBox,  // 20-35 cm across, walls 8-15 cm high: bottom + 4 walls
  kCan,      // a can or bottle, lying on its side (3 in 4) or standing
  kPlate,    // a disc 18-24 cm across, 1-2 cm thick
  kTablet,   // a box 20-25 x 14-17 cm, 1-2 cm thick
  // StackedPileOptions::more_kinds only:
  kDrill,   // standing: a battery block, a handle, a barrel across the top
            // and a chuck, in three colours (one object)
  kBanana,  // lying: a curved chain of 4 rounded segments, 16-20 cm long
  kPen,     // lying: a cylinder 12-15 cm long, 1.1-1.5 cm thick, and its cap
  kPart,    // a small flat part: 2.5-5 cm across, 1-1.5 cm thick (the
            // least height an object has, issue 48)
};

std::string_view StackedKindName(StackedKind kind);  // "book", "box", ...

// How a pile is built and seen. The defaults are the `stacked` set's.
struct StackedPileOptions {
  // Also the kinds real frames showed cut or missed: a drill, a banana, a
  // pen and small flat parts, and a tower of three boxes (drawn from the
  // same stream after the default plan's draws, so with this off a seed
  // gives the pile it gave before these kinds existed).
  bool more_kinds = false;
  // Seen from above: the camera 0.6-0.9 m above the table and at most
  // 0.25 m back from the pile's centre (looking down 70-90 degrees)
  // instead of 0.5-0.8 m back at 0.6-0.8 m up.
  bool from_above = false;
  // The frame, pixels (SensorIntrinsics scales the sensor's to it):
  // [160, 1920] x [120, 1080].
  int width = 640;
  int height = 480;
};

// OK, or INVALID_ARGUMENT naming the field.
absl::Status Validate(const StackedPileOptions& options);

// The default options at `sensor`'s own frame size (SensorFrameSize:
// 640 x 576 for time of flight, else 640 x 480): what the overloads
// without options use.
StackedPileOptions SensorPileOptions(RoomSensor sensor);

// The options of the `stacked-above` scorecard set: every kind, from
// above, at the sensor's usual resolution (the Kinect v1's 640 x 480, the
// active stereo's 1280 x 720, the time of flight's 640 x 576).
StackedPileOptions AbovePileOptions(RoomSensor sensor);

// A pile before rendering.
struct StackedPileSpec {
  // spec.objects[k] (and its object_parts) is object k; spec.intrinsics,
  // width and height are the sensor's (SensorIntrinsics at the options'
  // size).
  SceneSpec spec;
  std::vector<StackedKind> kinds;  // per object
  // Per object: -1 on the table, else the index j < k of the object it
  // rests on (inside, for a bowl or an open box).
  std::vector<int> rests_on;
};

// The pile of `seed` for `sensor`, deterministic in both (the sensor's
// intrinsics decide what is in view, so the two sensors give different
// piles for one seed). On return:
//   - 8-16 objects, at least 3 of them resting on another object, at least
//     one made of several primitives (a mug, an open box or a book);
//   - every object rests on the table (its lowest point at z = 0) or on the
//     object rests_on names (its lowest point on that object's top face,
//     on an open box's bottom or on a bowl's flat inner floor), and no two
//     objects interpenetrate (their vertical projections are disjoint
//     where their height intervals overlap; a cup in a bowl stands within
//     the bowl's flat floor);
//   - every object projects inside the image and keeps at least 35 % of the
//     pixels it covers alone, and 45 pixels, on a 320 x 240 ray cast (at
//     640 x 480: about 30 % and 180 pixels);
//   - the camera is 0.6-0.8 m above the table, 0.5-0.8 m back from the
//     pile's centre, looking at it, rolled by up to 3 degrees.
// On the rare draw that falls short of these counts the pile is drawn
// again from a stream derived from `seed`.
StackedPileSpec RandomStackedPileSpec(uint64_t seed, RoomSensor sensor);
// The same with `options` (the overload above: SensorPileOptions(sensor))
// (precondition, checked: Validate(options) is OK). Of the counts above, the
// visible share holds at any resolution.
StackedPileSpec RandomStackedPileSpec(uint64_t seed, RoomSensor sensor,
                                      const StackedPileOptions& options);

// A rendered pile.
struct StackedPile {
  // RandomStackedPileSpec rendered with RoomNoise(sensor), noise seeded by
  // `seed`: labels 10 * (k + 2) for object k and all its parts, 1 the
  // table, 2 floor, 3 wall, 0 no depth. frame.name is "stack-<tag><seed>",
  // the tag RoomSensorTag(sensor): "" for the Kinect v1, "as-" for active
  // stereo, "tof-" for time of flight.
  SynthScene scene;
  SceneSpec spec;                  // what was rendered
  std::vector<StackedKind> kinds;  // as StackedPileSpec
  std::vector<int> rests_on;       // as StackedPileSpec
};

StackedPile GenerateStackedPile(uint64_t seed, RoomSensor sensor);
// The same with `options`; frame.name "stack-above-<tag><seed>" when seen
// from above, else as above.
StackedPile GenerateStackedPile(uint64_t seed, RoomSensor sensor,
                                const StackedPileOptions& options);

// The number of objects resting on another object (rests_on >= 0).
int CountStacked(const std::vector<int>& rests_on);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_STACKED_SCENE_H_
