#include "server/status_util.h"

#include <string>

#include "gtest/gtest.h"

namespace fovea::server {
namespace {

TEST(StatusUtilTest, OkBecomesOk) {
  EXPECT_TRUE(ToGrpcStatus(absl::OkStatus()).ok());
}

TEST(StatusUtilTest, EveryCodeKeepsItsNumberAndMessage) {
  for (absl::StatusCode code : kAllStatusCodes) {
    if (code == absl::StatusCode::kOk) continue;
    const grpc::Status status =
        ToGrpcStatus(absl::Status(code, "frame.color.step: too small"));
    EXPECT_EQ(static_cast<int>(status.error_code()), static_cast<int>(code))
        << absl::StatusCodeToString(code);
    EXPECT_EQ(status.error_message(), "frame.color.step: too small");
  }
}

TEST(StatusUtilTest, NonCanonicalCodeIsUnknown) {
  const grpc::Status status =
      ToGrpcStatus(absl::Status(static_cast<absl::StatusCode>(42), "odd"));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNKNOWN);
  EXPECT_EQ(status.error_message(), "odd");
}

TEST(StatusUtilTest, CodeNamesAreSpelledAsGrpcGoSpellsThem) {
  // google.golang.org/grpc/codes, Code.String().
  const std::string expected[] = {"OK",
                                  "Canceled",
                                  "Unknown",
                                  "InvalidArgument",
                                  "DeadlineExceeded",
                                  "NotFound",
                                  "AlreadyExists",
                                  "PermissionDenied",
                                  "ResourceExhausted",
                                  "FailedPrecondition",
                                  "Aborted",
                                  "OutOfRange",
                                  "Unimplemented",
                                  "Internal",
                                  "Unavailable",
                                  "DataLoss",
                                  "Unauthenticated"};
  ASSERT_EQ(std::size(expected), kAllStatusCodes.size());
  for (size_t i = 0; i < kAllStatusCodes.size(); ++i) {
    EXPECT_EQ(static_cast<size_t>(kAllStatusCodes[i]), i);
    EXPECT_EQ(GrpcCodeName(kAllStatusCodes[i]), expected[i]);
  }
  EXPECT_EQ(GrpcCodeName(static_cast<absl::StatusCode>(42)), "Unknown");
}

}  // namespace
}  // namespace fovea::server
