#ifndef FOVEA_CORE_SYNTH_STACKED_BODIES_H_
#define FOVEA_CORE_SYNTH_STACKED_BODIES_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The household objects of stacked piles (stacked_scene.cc): each kind's
// primitives, the volumes that keep others out and the surface others may
// rest on. Metres; a body is built in its own frame, standing on z = 0
// around the origin, and posed into the world by PosePileBody.

struct PileBody {
  StackedKind kind = StackedKind::kBox;
  // primitives[0] is the object's SceneSpec::objects entry, the others its
  // object_parts.
  std::vector<Primitive> primitives;
  // Upright prisms (footprint x height interval) whose union holds every
  // primitive: two bodies whose solids do not Collide do not interpenetrate.
  std::vector<Footprint> solids;
  // The whole body's vertical projection and height interval (for view
  // and table checks, and to place bodies next to each other).
  Footprint hull;
  // Where other bodies may rest: an area (z_min == z_max, its height) that
  // a resting body's hull must lie within; none for cups, mugs and cans.
  std::optional<Footprint> top;
  // Bodies resting on `top` are inside this one (a bowl's floor): they are
  // kept clear of it by construction (within its flat floor), not by its
  // solids, which fill its cavity.
  bool cavity = false;
};

// A body of `kind` in household colours that differ from `table_rgb`,
// small enough that its hull fits a support area whose smaller half size
// (or radius) is `room` (infinity on the table), or nullopt when the kind
// cannot be that small.
std::optional<PileBody> MakePileBody(StackedKind kind, float room,
                                     const Eigen::Vector3f& table_rgb,
                                     Random& rng);

// Whether a body of `kind` may rest on the top of one of kind `support`:
// books carry anything but open boxes; boxes carry boxes, cups, cans, pens
// and parts; tablets those, mugs and bananas; open boxes boxes, cups, mugs
// and cans; plates cups, mugs, bananas and parts; bowls cups. Drills,
// bananas, pens and parts carry nothing.
bool CanRestOn(StackedKind kind, StackedKind support);

// An axis-aligned box primitive centred at `centre` with half sizes
// `half`, metres.
Primitive BoxPrimitive(const Eigen::Vector3f& centre,
                       const Eigen::Vector3f& half, const Eigen::Vector3f& rgb,
                       Texture texture = Texture::kFlat);

// `body` turned by `yaw` (radians, about +z), its origin moved to (xy,
// base_z): primitives, solids, hull and top alike.
PileBody PosePileBody(const PileBody& body, const Eigen::Vector2f& xy,
                      float base_z, float yaw);

// Whether footprint `f` lies within `area` (a rectangle or a disc).
bool FitsInside(const Footprint& f, const Footprint& area);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_STACKED_BODIES_H_
