#ifndef FOVEA_CORE_BASE_GUARDED_H_
#define FOVEA_CORE_BASE_GUARDED_H_

#include <exception>
#include <new>
#include <string_view>
#include <type_traits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/strings.h"

namespace fovea {

// The exception boundary of core/: nothing throws out of a core function,
// but OpenCV, PCL, qhull's wrapper and the standard library can throw
// inside one. Guarded runs `body` (returning absl::Status or
// absl::StatusOr<T>) and turns what it throws into a status naming `what`:
//   std::bad_alloc          RESOURCE_EXHAUSTED "<what>: out of memory"
//   std::exception (and     INTERNAL "<what>: <e.what()>"
//   cv::Exception)
// Anything else propagates (core throws nothing of another type).
//
//   return Guarded("segment", [&] { return RunSegmentUnguarded(...); });
template <typename Body>
std::invoke_result_t<Body&> Guarded(std::string_view what, Body&& body) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat(AbslView(what), ": out of memory"));
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat(AbslView(what), ": ", e.what()));
  }
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_GUARDED_H_
