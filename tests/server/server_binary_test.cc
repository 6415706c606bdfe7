// The fovea-server executable: --help, bad flags, and a clean exit on
// SIGTERM.

#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/test_util.h"

#ifndef FOVEA_SERVER_BINARY
#error "FOVEA_SERVER_BINARY must name the built fovea-server"
#endif

namespace fovea::server {
namespace {

using ::fovea::server::testing::FreePort;
using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

// Starts fovea-server with `args`; returns its pid.
pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string binary = FOVEA_SERVER_BINARY;
  argv.push_back(binary.data());
  std::vector<std::string> copies = args;
  for (std::string& arg : copies) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Waits (bounded) for `pid` to exit; its wait status, or -1.
int WaitExit(pid_t pid, std::chrono::milliseconds timeout) {
  int status = -1;
  const bool exited =
      WaitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, timeout);
  return exited ? status : -1;
}

// Output and wait status of fovea-server run with `args` to completion.
std::pair<std::string, int> RunToCompletion(const std::string& args) {
  const std::string command =
      std::string(FOVEA_SERVER_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    output.append(buffer, n);
  }
  const int status = pclose(pipe);
  return {output, status};
}

TEST(ServerBinaryTest, HelpListsEveryFlagWithItsDefault) {
  const auto [output, status] = RunToCompletion("--help");
  for (const char* flag : {"--listen", "--metrics_listen", "--concurrency",
                           "--queue", "--max_message_bytes", "--max_width",
                           "--max_height", "--grace_period_s", "--log_level"}) {
    EXPECT_THAT(output, HasSubstr(flag));
  }
  EXPECT_THAT(output, HasSubstr("default: 67108864"));
  EXPECT_THAT(output, HasSubstr("default: \"0.0.0.0:50051\""));
}

TEST(ServerBinaryTest, BadFlagValueExitsNonZeroNamingIt) {
  const auto [output, status] =
      RunToCompletion("--concurrency=0 --metrics_listen=");
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_THAT(output, HasSubstr("--concurrency"));
}

TEST(ServerBinaryTest, ExitsZeroOnSigtermAfterServing) {
  const int port = FreePort();
  const pid_t pid =
      Spawn({"--listen=127.0.0.1:" + std::to_string(port),
             "--metrics_listen=127.0.0.1:" + std::to_string(FreePort()),
             "--concurrency=1", "--grace_period_s=5"});
  ASSERT_GT(pid, 0);
  const std::string target = "127.0.0.1:" + std::to_string(port);
  // A fresh channel per attempt: a channel that tried before the server
  // listened may wait out gRPC's reconnect backoff (seconds).
  auto health = [&target](const std::string& service) {
    return HealthStatus(
        grpc::CreateChannel(target, grpc::InsecureChannelCredentials()),
        service);
  };
  int status = 0;
  bool exited = false;
  const bool serving = WaitFor(
      [&] {
        exited = waitpid(pid, &status, WNOHANG) == pid;
        return exited || health("fovea.v1.Perception") == "SERVING";
      },
      std::chrono::seconds(60));
  ASSERT_FALSE(exited) << "exited early, wait status " << status;
  ASSERT_TRUE(serving);
  EXPECT_EQ(health(""), "SERVING");

  ASSERT_EQ(kill(pid, SIGTERM), 0);
  status = WaitExit(pid, std::chrono::seconds(30));
  if (status == -1) kill(pid, SIGKILL);
  ASSERT_NE(status, -1) << "did not exit within 30 s of SIGTERM";
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
}  // namespace fovea::server
