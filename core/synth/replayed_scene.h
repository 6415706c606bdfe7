#ifndef FOVEA_CORE_SYNTH_REPLAYED_SCENE_H_
#define FOVEA_CORE_SYNTH_REPLAYED_SCENE_H_

#include <cstdint>

#include "absl/types/span.h"
#include "core/base/name_table.h"
#include "core/frame/osd_pcd.h"
#include "core/synth/sequence.h"

namespace fovea::synth {

// A real labelled frame (an OSD scene) replayed as a frame stream: what a
// robot's camera would have sent had it kept looking at that scene.
enum class ReplayKind {
  kNoise,   // the same view, fresh sensor noise every frame
  kShift,   // the camera drifting up to 3 cm and 1.5 degrees (re-projected)
  kRemove,  // objects taken away one at a time, highest first
};

// "noise", "shift", "remove".
absl::Span<const NamedValue<ReplayKind>> ReplayKinds();

// Plays `labelled` (labels as LoadOsdPcd's; table labels 1-9 needed for
// kRemove) as `kind` over `frames` (>= 2) frames. Every frame, the first
// included, gets fresh Kinect v1 noise on top of the sensor's own: axial
// Gaussian noise of sigma 1.43e-3 z^2 quantised to its disparity steps,
// dropouts at depth edges, colour noise. The ground-truth objects are the
// scene's objects, except that the disjoint parts of an occluded object
// count apart: one truth is the parts of one object (labels >= 20 of one
// ObjectId) that touch within 2 px, directly or through each other, and
// SequenceFrame::object_ids holds their lowest label. (mOSD labels apart
// both an object's faces across a depth edge, such as a mug's inside and
// outside, which touch, and the parts an occluder separates.) The world is
// the first frame's camera: camera_to_world is the identity except for
// kShift.
//   kShift: each frame is the scene's points seen from the moved camera,
//   nearest point winning, one-pixel cracks filled; what the first view did
//   not see has no depth.
//   kRemove: a removed object's pixels become the table: depth where the
//   pixel's ray meets the table's plane (fitted to its labelled points),
//   colour inpainted from around; an object resting on another is taken
//   first. One object stays.
// Deterministic in (scene, kind, seed, frames).
Sequence ReplayAsSequence(const LabelledFrame& labelled, ReplayKind kind,
                          uint64_t seed, int frames = 12);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_REPLAYED_SCENE_H_
