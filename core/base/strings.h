#ifndef FOVEA_CORE_BASE_STRINGS_H_
#define FOVEA_CORE_BASE_STRINGS_H_

#include <string_view>

#include "absl/strings/string_view.h"

namespace fovea {

// Debian 12's abseil is built with its own string_view
// (ABSL_OPTION_USE_STD_STRING_VIEW is 0), which absl::StrCat, StrSplit and
// friends take; the project's headers speak std::string_view. This views
// the same characters as the other type.
inline absl::string_view AbslView(std::string_view s) {
  return {s.data(), s.size()};
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_STRINGS_H_
