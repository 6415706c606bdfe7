#ifndef FOVEA_TESTS_TESTING_RUN_COMMAND_H_
#define FOVEA_TESTS_TESTING_RUN_COMMAND_H_

// Runs a program through the shell for tests of the command-line tools.

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "gtest/gtest.h"

namespace fovea::testing {

// What a run of a command did.
struct CommandRun {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;     // stdout
  std::string err;     // stderr
};

// Runs `command` through /bin/sh, capturing stdout and stderr separately.
// stderr goes through a file of its own per run: ctest runs test binaries
// in parallel, and a shared file would mix their output.
inline CommandRun RunCommand(const std::string& command) {
  std::string err_path = ::testing::TempDir() + "/fovea_command_stderr_XXXXXX";
  const int fd = mkstemp(err_path.data());
  if (fd >= 0) close(fd);
  CommandRun run;
  FILE* pipe = popen((command + " 2>" + err_path).c_str(), "r");
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

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_TESTING_RUN_COMMAND_H_
