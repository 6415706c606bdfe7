#include "core/segmentation/svm_common.h"

#include <cmath>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"

namespace fovea::svm_internal {
uint64_t Fnv1a(std::string_view text) {
  uint64_t hash = 14695981039346656037ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  return hash;
}

absl::StatusOr<double> ParseNumber(std::string_view text, int line) {
  double value = 0.0;
  if (!absl::SimpleAtod(AbslView(text), &value) || !std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "line ", line, ": '", AbslView(text), "' is not a finite number"));
  }
  return value;
}

}  // namespace fovea::svm_internal
