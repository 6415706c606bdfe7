#ifndef FOVEA_SERVER_STATUS_UTIL_H_
#define FOVEA_SERVER_STATUS_UTIL_H_

#include <grpcpp/support/status.h>

#include <array>
#include <string_view>

#include "absl/status/status.h"

namespace fovea::server {

// The one error boundary of the server: every grpc::Status a handler
// returns is made here from an absl::Status. absl and gRPC share the
// canonical codes (google.rpc.Code), so the mapping is one to one and
// keeps the message; payloads are dropped. A code outside the canonical
// 17 becomes UNKNOWN.
grpc::Status ToGrpcStatus(const absl::Status& status);

// The canonical codes in numeric order, OK (0) to UNAUTHENTICATED (16).
inline constexpr std::array<absl::StatusCode, 17> kAllStatusCodes = {
    absl::StatusCode::kOk,
    absl::StatusCode::kCancelled,
    absl::StatusCode::kUnknown,
    absl::StatusCode::kInvalidArgument,
    absl::StatusCode::kDeadlineExceeded,
    absl::StatusCode::kNotFound,
    absl::StatusCode::kAlreadyExists,
    absl::StatusCode::kPermissionDenied,
    absl::StatusCode::kResourceExhausted,
    absl::StatusCode::kFailedPrecondition,
    absl::StatusCode::kAborted,
    absl::StatusCode::kOutOfRange,
    absl::StatusCode::kUnimplemented,
    absl::StatusCode::kInternal,
    absl::StatusCode::kUnavailable,
    absl::StatusCode::kDataLoss,
    absl::StatusCode::kUnauthenticated,
};

// A code as gRPC-Go's codes.Code.String() spells it ("OK", "Canceled",
// "InvalidArgument", ...): the `grpc_code` label of go-grpc-prometheus and
// the code in the server's log lines. "Unknown" for a non-canonical code.
std::string_view GrpcCodeName(absl::StatusCode code);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_STATUS_UTIL_H_
