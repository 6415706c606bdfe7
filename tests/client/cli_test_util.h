#ifndef FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_
#define FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_

#include <string>

#include "absl/strings/str_cat.h"
#include "tests/testing/run_command.h"

namespace fovea::client {

// What a run of the fovea-client binary did.
using CliRun = ::fovea::testing::CommandRun;

// Runs `FOVEA_CLIENT_BIN args` through the shell (args are pasted as is).
inline CliRun RunCli(const std::string& args) {
  return ::fovea::testing::RunCommand(
      absl::StrCat(FOVEA_CLIENT_BIN, " ", args));
}

}  // namespace fovea::client

#endif  // FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_
