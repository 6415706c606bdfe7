#ifndef FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_
#define FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"

namespace fovea::client {

// What a run of the fovea-client binary did.
struct CliRun {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;     // stdout
  std::string err;     // stderr
};

// Runs `FOVEA_CLIENT_BIN args` through the shell (args are pasted as is).
inline CliRun RunCli(const std::string& args) {
  // One file per run: ctest runs test binaries in parallel, and a shared
  // file would mix their stderr.
  std::string err_path =
      absl::StrCat(::testing::TempDir(), "/fovea_client_cli_stderr_XXXXXX");
  const int fd = mkstemp(err_path.data());
  if (fd >= 0) close(fd);
  const std::string command =
      absl::StrCat(FOVEA_CLIENT_BIN, " ", args, " 2>", err_path);
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    run.out.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  if (WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
  std::ifstream err(err_path);
  run.err.assign(std::istreambuf_iterator<char>(err),
                 std::istreambuf_iterator<char>());
  std::remove(err_path.c_str());
  return run;
}

}  // namespace fovea::client

#endif  // FOVEA_TESTS_CLIENT_CLI_TEST_UTIL_H_
