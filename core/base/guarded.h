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

// The one exception boundary of a call. Core functions return a status for
// every error they can name and catch nothing: what OpenCV, PCL, libsvm or
// the standard library throw underneath them (out of memory, a library's
// bug) passes through to the place where a call becomes a status, which
// calls Guarded once: the server's job for each RPC
// (server/perception_service.cc). The tools and the fuzz targets have no
// boundary: there an exception ends the process with its what() printed,
// which is what a bug should do. Guarded runs `body`
// (returning absl::Status or absl::StatusOr<T>) and turns what it throws
// into a status naming `what`:
//   std::bad_alloc          RESOURCE_EXHAUSTED "<what>: out of memory"
//   std::exception (and     INTERNAL "<what>: unexpected exception: <what()>"
//   cv::Exception)
//   anything else           INTERNAL "<what>: unexpected exception of a
//                           non-standard type"
//
//   status = Guarded("Detect", [&] { return Compute(); });
template <typename Body>
std::invoke_result_t<Body&> Guarded(std::string_view what, Body&& body) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat(AbslView(what), ": out of memory"));
  } catch (const std::exception& e) {
    return absl::InternalError(
        absl::StrCat(AbslView(what), ": unexpected exception: ", e.what()));
  } catch (...) {
    return absl::InternalError(absl::StrCat(
        AbslView(what), ": unexpected exception of a non-standard type"));
  }
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_GUARDED_H_
