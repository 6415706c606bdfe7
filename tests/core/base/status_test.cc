#include "absl/status/status.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "absl/status/statusor.h"
#include "core/base/guarded.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

using ::testing::HasSubstr;

absl::StatusOr<int> Half(int x) {
  if (x % 2 != 0) return absl::InvalidArgumentError("odd");
  return x / 2;
}

// A quarter through two halvings; the first failure comes back as is.
absl::StatusOr<int> Quarter(int x, int* evaluations) {
  ++*evaluations;
  FOVEA_ASSIGN_OR_RETURN(const int half, Half(x));
  int quarter = 0;
  FOVEA_ASSIGN_OR_RETURN(quarter, Half(half));  // into an existing lvalue
  return quarter;
}

absl::Status CheckEven(int x) {
  FOVEA_RETURN_IF_ERROR(Half(x));  // a StatusOr
  FOVEA_RETURN_IF_ERROR(x >= 0 ? absl::OkStatus()
                               : absl::OutOfRangeError("negative"));
  return absl::OkStatus();
}

TEST(StatusMacros, AssignOrReturnPassesValuesAndFirstErrors) {
  int evaluations = 0;
  EXPECT_EQ(*Quarter(12, &evaluations), 3);
  EXPECT_EQ(Quarter(6, &evaluations).status().message(), "odd");  // 2nd
  EXPECT_EQ(Quarter(5, &evaluations).status().message(), "odd");  // 1st
  EXPECT_EQ(evaluations, 3);
}

TEST(StatusMacros, ReturnIfErrorTakesStatusAndStatusOr) {
  EXPECT_TRUE(CheckEven(4).ok());
  EXPECT_EQ(CheckEven(3).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CheckEven(-2).code(), absl::StatusCode::kOutOfRange);
}

// A move-only value is moved out, not copied.
absl::StatusOr<std::unique_ptr<int>> MakeBox(int x) {
  return std::make_unique<int>(x);
}
absl::StatusOr<int> Unbox(int x) {
  FOVEA_ASSIGN_OR_RETURN(std::unique_ptr<int> box, MakeBox(x));
  return *box;
}

TEST(StatusMacros, AssignOrReturnMovesMoveOnlyValues) {
  EXPECT_EQ(*Unbox(7), 7);
}

TEST(Guarded, TurnsWhatIsThrownIntoAStatusNamingTheOperation) {
  const absl::Status oom =
      Guarded("decode", []() -> absl::Status { throw std::bad_alloc(); });
  EXPECT_EQ(oom.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(oom.message(), "decode: out of memory");

  const absl::StatusOr<int> bug = Guarded("fit", []() -> absl::StatusOr<int> {
    throw std::runtime_error("matrix not positive definite");
  });
  EXPECT_EQ(bug.status().code(), absl::StatusCode::kInternal);
  EXPECT_THAT(bug.status().message(),
              HasSubstr("fit: unexpected exception: matrix not positive"));
  const absl::Status odd = Guarded("fit", []() -> absl::Status { throw 7; });
  EXPECT_EQ(odd.code(), absl::StatusCode::kInternal);
  EXPECT_EQ(odd.message(), "fit: unexpected exception of a non-standard type");

  const absl::StatusOr<int> fine =
      Guarded("fit", []() -> absl::StatusOr<int> { return 4; });
  EXPECT_EQ(*fine, 4);
}

}  // namespace
}  // namespace fovea
