#ifndef FOVEA_TOOLS_EVAL_SCENE_KIND_H_
#define FOVEA_TOOLS_EVAL_SCENE_KIND_H_

#include <string>
#include <string_view>

namespace fovea::eval {

// Kind of an OSD learn scene from its name (shared/data/README.md):
// learn 0-16 boxes, 17-24 stacked boxes, 25-32 occluded objects,
// 33-44 cylindric objects. "other" for any other name.
std::string SceneKind(std::string_view name);

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_SCENE_KIND_H_
