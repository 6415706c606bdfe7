#ifndef FOVEA_CORE_SYNTH_SEQUENCE_H_
#define FOVEA_CORE_SYNTH_SEQUENCE_H_

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/types/span.h"
#include "core/base/name_table.h"
#include "core/frame/osd_pcd.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The scene generators played as frame streams with ground-truth
// identities: what a robot's camera sees while it looks, reaches and
// manipulates. Each frame is rendered with fresh sensor noise (Kinect v1).
enum class SequenceKind {
  kStatic,        // a still camera on a still scene
  kDrift,         // a robot's head: slow drift of a few cm and mm shake
  kApproach,      // a wrist camera closing in, 0.75 -> 0.45 of its distance
  kPlace,         // objects placed one at a time
  kRemove,        // objects taken away one at a time
  kPush,          // one object pushed 1 cm a frame across the table
  kPickAndPlace,  // one object lifted out of view, put down elsewhere
  // Two objects side by side swept along together 3 cm a frame for the
  // first half (what moves as one is one object), then one pulled away
  // 3 cm a frame while the other stays (parts that move apart split).
  // Moving 3 cm a frame, more than the tracker's moved_m.
  kPushApart,
};

// "static", "drift", "approach", "place", "remove", "push", "pick-place",
// "push-apart".
absl::Span<const NamedValue<SequenceKind>> SequenceKinds();

struct SequenceFrame {
  // labels as RenderScene's: 10 * (k + 2) for the k-th object present in
  // this frame.
  LabelledFrame frame;
  // The k-th present object's identity in the sequence (its index in the
  // sequence's first spec): the same object has the same id in every frame.
  std::vector<int> object_ids;
  Eigen::Isometry3f camera_to_world = Eigen::Isometry3f::Identity();
};

struct Sequence {
  std::string name;  // "<kind>-<seed>"
  std::vector<SequenceFrame> frames;
};

// A household table scene of 3-7 objects (none stacked, so that any may be
// taken away) played as `kind` over `frames` frames (>= 2). Deterministic
// in (kind, seed, frames).
Sequence GenerateSequence(SequenceKind kind, uint64_t seed, int frames = 12);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_SEQUENCE_H_
