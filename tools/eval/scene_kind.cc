#include "tools/eval/scene_kind.h"

#include <charconv>

namespace fovea::eval {

std::string SceneKind(std::string_view name) {
  constexpr std::string_view kLearn = "learn";
  if (name.substr(0, kLearn.size()) != kLearn) return "other";
  int index = -1;
  const std::string_view digits = name.substr(kLearn.size());
  const auto [ptr, ec] =
      std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (ec != std::errc() || ptr != digits.data() + digits.size()) return "other";
  if (index >= 0 && index <= 16) return "boxes";
  if (index >= 17 && index <= 24) return "stacked";
  if (index >= 25 && index <= 32) return "occluded";
  if (index >= 33 && index <= 44) return "cylindric";
  return "other";
}

}  // namespace fovea::eval
