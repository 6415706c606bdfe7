#include "server/env_flags.h"

#include <map>
#include <string>

#include "absl/flags/flag.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

ABSL_FLAG(int, env_test_count, 1, "A flag for this test.");
ABSL_FLAG(std::string, env_test_address, "a:1", "A flag for this test.");

namespace fovea::server {
namespace {

using ::testing::HasSubstr;

// An environment made of `variables`.
GetEnv FakeEnv(std::map<std::string, std::string> variables) {
  return [variables = std::move(variables)](const char* name) -> const char* {
    const auto it = variables.find(name);
    return it == variables.end() ? nullptr : it->second.c_str();
  };
}

class EnvFlagsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::SetFlag(&FLAGS_env_test_count, 1);
    absl::SetFlag(&FLAGS_env_test_address, "a:1");
  }
};

TEST_F(EnvFlagsTest, VariableIsPrefixedUpperCaseFlagName) {
  EXPECT_EQ(EnvVariableForFlag("metrics_listen"), "FOVEA_METRICS_LISTEN");
  EXPECT_EQ(EnvVariableForFlag("grace_period_s"), "FOVEA_GRACE_PERIOD_S");
}

TEST_F(EnvFlagsTest, SetVariablesSetTheirFlagsAndUnsetOnesLeaveDefaults) {
  ASSERT_TRUE(ApplyFlagsFromEnv({"env_test_count", "env_test_address"},
                                FakeEnv({{"FOVEA_ENV_TEST_COUNT", "7"}}))
                  .ok());
  EXPECT_EQ(absl::GetFlag(FLAGS_env_test_count), 7);
  EXPECT_EQ(absl::GetFlag(FLAGS_env_test_address), "a:1");

  ASSERT_TRUE(ApplyFlagsFromEnv({"env_test_address"},
                                FakeEnv({{"FOVEA_ENV_TEST_ADDRESS", ""}}))
                  .ok());
  EXPECT_EQ(absl::GetFlag(FLAGS_env_test_address), "");
}

TEST_F(EnvFlagsTest, UnparsableValueIsInvalidArgumentNamingTheVariable) {
  const absl::Status status = ApplyFlagsFromEnv(
      {"env_test_count"}, FakeEnv({{"FOVEA_ENV_TEST_COUNT", "seven"}}));
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("FOVEA_ENV_TEST_COUNT"));
  EXPECT_THAT(status.message(), HasSubstr("seven"));
  EXPECT_EQ(absl::GetFlag(FLAGS_env_test_count), 1);
}

TEST_F(EnvFlagsTest, UnknownFlagIsAnInternalError) {
  const absl::Status status =
      ApplyFlagsFromEnv({"env_test_no_such_flag"},
                        FakeEnv({{"FOVEA_ENV_TEST_NO_SUCH_FLAG", "1"}}));
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal);
}

}  // namespace
}  // namespace fovea::server
