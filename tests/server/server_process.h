// A fovea-server process for the tests of the executable
// (server_binary_test.cc, server_binary_shutdown_test.cc): started on free
// loopback ports, waited for until it serves, and stopped with SIGTERM.
// FOVEA_SERVER_BINARY names the built fovea-server (a compile definition
// of the tests that include this).

#ifndef FOVEA_TESTS_SERVER_SERVER_PROCESS_H_
#define FOVEA_TESTS_SERVER_SERVER_PROCESS_H_

#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "tests/server/test_util.h"

#ifndef FOVEA_SERVER_BINARY
#error "FOVEA_SERVER_BINARY must name the built fovea-server"
#endif

namespace fovea::server::testing {

// Starts fovea-server with `args` (and a soft and hard RLIMIT_NOFILE of
// `nofile` when positive); returns its pid.
inline pid_t Spawn(const std::vector<std::string>& args, int nofile = 0) {
  std::vector<char*> argv;
  std::string binary = FOVEA_SERVER_BINARY;
  argv.push_back(binary.data());
  std::vector<std::string> copies = args;
  for (std::string& arg : copies) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (nofile > 0) {
      const rlimit limit{static_cast<rlim_t>(nofile),
                         static_cast<rlim_t>(nofile)};
      if (setrlimit(RLIMIT_NOFILE, &limit) != 0) _exit(126);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Waits (bounded) for `pid` to exit; its wait status, or -1.
inline int WaitExit(pid_t pid, std::chrono::milliseconds timeout) {
  int status = -1;
  const bool exited =
      WaitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, timeout);
  return exited ? status : -1;
}

// A fovea-server process on loopback, started with `flags` plus --listen
// and --metrics_listen on free ports.
struct ServerProcess {
  pid_t pid = -1;
  std::string target;  // host:port of the gRPC server
  int metrics_port = 0;
};

// Starts fovea-server with `flags` plus --listen on a free port (and
// --metrics_listen on another, unless `flags` set it) and waits up to 60 s
// until `ready(target)`. A port FreePort() found free can be taken before
// the child binds it (as the source port of another test's connection): a
// child that exits early is started again on fresh ports, twice at most.
// Fails the test (ADD_FAILURE) and returns pid -1 when it never gets ready.
inline ServerProcess StartUntil(
    const std::vector<std::string>& flags,
    const std::function<bool(const std::string& target)>& ready,
    int nofile = 0) {
  constexpr int kAttempts = 3;
  const bool metrics_set =
      std::any_of(flags.begin(), flags.end(), [](const std::string& flag) {
        return flag.rfind("--metrics_listen=", 0) == 0;
      });
  ServerProcess server;
  int status = 0;
  bool exited = false;
  bool serving = false;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    server.target = "127.0.0.1:" + std::to_string(FreePort());
    std::vector<std::string> args = flags;
    args.push_back("--listen=" + server.target);
    if (!metrics_set) {
      server.metrics_port = FreePort();
      args.push_back("--metrics_listen=127.0.0.1:" +
                     std::to_string(server.metrics_port));
    }
    server.pid = Spawn(args, nofile);
    if (server.pid <= 0) {
      ADD_FAILURE() << "fork failed";
      return server;
    }
    exited = false;
    serving = WaitFor(
        [&] {
          exited = waitpid(server.pid, &status, WNOHANG) == server.pid;
          return exited || ready(server.target);
        },
        std::chrono::seconds(60));
    if (!exited) break;
  }
  if (exited || !serving) {
    ADD_FAILURE() << (exited ? "exited early " + std::to_string(kAttempts) +
                                   " times, last wait status " +
                                   std::to_string(status)
                             : std::string("not ready within 60 s"));
    if (!exited) {
      kill(server.pid, SIGKILL);
      waitpid(server.pid, &status, 0);
    }
    server.pid = -1;
  }
  return server;
}

// StartUntil health is SERVING on both names.
inline ServerProcess StartServing(const std::vector<std::string>& flags,
                                  int nofile = 0) {
  // A fresh channel per attempt: a channel that tried before the server
  // listened may wait out gRPC's reconnect backoff (seconds).
  const auto health = [](const std::string& target,
                         const std::string& service) {
    return HealthStatus(
        grpc::CreateChannel(target, grpc::InsecureChannelCredentials()),
        service);
  };
  ServerProcess server = StartUntil(
      flags,
      [&](const std::string& target) {
        return health(target, "fovea.v1.Perception") == "SERVING";
      },
      nofile);
  if (server.pid > 0 && health(server.target, "") != "SERVING") {
    ADD_FAILURE() << "\"\" not SERVING";
    kill(server.pid, SIGKILL);
    waitpid(server.pid, nullptr, 0);
    server.pid = -1;
  }
  return server;
}

// Sends SIGTERM and expects exit code 0 within 30 s.
inline void ExpectCleanExitOnSigterm(pid_t pid) {
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  const int status = WaitExit(pid, std::chrono::seconds(30));
  if (status == -1) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  ASSERT_NE(status, -1) << "did not exit within 30 s of SIGTERM";
  EXPECT_TRUE(WIFEXITED(status)) << "wait status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace fovea::server::testing

#endif  // FOVEA_TESTS_SERVER_SERVER_PROCESS_H_
