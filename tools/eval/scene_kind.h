#ifndef FOVEA_TOOLS_EVAL_SCENE_KIND_H_
#define FOVEA_TOOLS_EVAL_SCENE_KIND_H_

#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace fovea::eval {

// The kind of a scene from its name, for the per-kind tables. A name is a
// prefix and a number ("learn12", "test40", "pile-7"); a kind covers a
// range of numbers of one prefix. Built in (shared/data/osd's README):
//   learn  0-16 boxes, 17-24 stacked, 25-32 occluded, 33-44 cylindric;
//   test   0-15 boxes, 16-23 stacked, 24-30 occluded, 31-42 cylindric,
//          43-54 mixed, 55-64 complex;
//   pile-  every number: pile (core/synth GeneratePile);
//   room-  every number: room.
// "other" for any other name.
std::string SceneKind(std::string_view name);

// Adds the kinds of `path`, a text file of lines "PREFIX FIRST-LAST KIND"
// ('#' starts a comment), ahead of the built-in ones (a folder's own
// kinds.txt). NOT_FOUND without the file; INVALID_ARGUMENT naming the
// line for a malformed one.
absl::Status LoadKinds(const std::string& path);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SCENE_KIND_H_
