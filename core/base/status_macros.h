#ifndef FOVEA_CORE_BASE_STATUS_MACROS_H_
#define FOVEA_CORE_BASE_STATUS_MACROS_H_

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

// The one way to pass an error up (Debian 12's abseil has no
// status_macros.h of its own):
//
//   FOVEA_RETURN_IF_ERROR(Validate(options));
//   FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud, BuildOrganizedCloud(f, n));
//   FOVEA_ASSIGN_OR_RETURN(scene.plane, FindSupportPlane(cloud, o, s));
//
// FOVEA_RETURN_IF_ERROR(expr): `expr` is an absl::Status or an
// absl::StatusOr<T>; when it is not OK, the enclosing function returns its
// status. FOVEA_ASSIGN_OR_RETURN(lhs, expr): `expr` is an
// absl::StatusOr<T>; when OK its value is moved into `lhs` (a declaration
// or an lvalue), else the enclosing function returns its status. Each is
// one statement; `expr` is evaluated exactly once.

namespace fovea::status_internal {

inline const absl::Status& AsStatus(const absl::Status& status) {
  return status;
}
template <typename T>
const absl::Status& AsStatus(const absl::StatusOr<T>& status_or) {
  return status_or.status();
}

}  // namespace fovea::status_internal

#define FOVEA_STATUS_CONCAT_INNER_(a, b) a##b
#define FOVEA_STATUS_CONCAT_(a, b) FOVEA_STATUS_CONCAT_INNER_(a, b)

#define FOVEA_RETURN_IF_ERROR(expr)                                   \
  do {                                                                \
    if (const auto& fovea_status_or_ = (expr);                        \
        !::fovea::status_internal::AsStatus(fovea_status_or_).ok()) { \
      return ::fovea::status_internal::AsStatus(fovea_status_or_);    \
    }                                                                 \
  } while (false)

#define FOVEA_ASSIGN_OR_RETURN(lhs, expr) \
  FOVEA_ASSIGN_OR_RETURN_IMPL_(           \
      FOVEA_STATUS_CONCAT_(fovea_status_or_, __LINE__), lhs, expr)

#define FOVEA_ASSIGN_OR_RETURN_IMPL_(status_or, lhs, expr)   \
  auto status_or = (expr);                                   \
  if (!status_or.ok()) return std::move(status_or).status(); \
  lhs = *std::move(status_or)

#endif  // FOVEA_CORE_BASE_STATUS_MACROS_H_
