#ifndef FOVEA_TESTS_SERVER_SERVER_FIXTURE_H_
#define FOVEA_TESTS_SERVER_SERVER_FIXTURE_H_

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <string>

#include "core/base/mutex.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/server.h"

namespace fovea::server::testing {

inline constexpr auto kStartTimeout = std::chrono::seconds(60);
inline constexpr auto kCallTimeout = std::chrono::seconds(30);

// Holds the threads that pass it while closed; tests use it (through the
// server's test hooks) to keep a worker busy, fill the queue or stop a job
// at a stage boundary, without sleeping.
class Gate {
 public:
  // Every later Pass waits until Open.
  void Close();
  // Passes go through until the `n`-th (counted from the first Pass ever,
  // 1-based), which closes the gate: it and every later Pass wait until
  // Open.
  void CloseAtPass(int n);
  void Open();
  // Passes so far, held ones included.
  int entered() const;
  // The hook: counts, then waits while the gate is closed.
  void Pass();

 private:
  mutable Mutex mu_;
  bool open_ ABSL_GUARDED_BY(mu_) = true;
  int close_at_ ABSL_GUARDED_BY(mu_) = 0;  // 0: never
  int entered_ ABSL_GUARDED_BY(mu_) = 0;
};

// An in-process FoveaServer on loopback with a channel and stub to it.
// The server's test hooks are wired to `gate_` (start of each Detect job,
// where ThrowInNextJob also acts), `stage_gate_` (each stage boundary) and
// stream_cancels() (each cancellation gRPC reports to a stream).
class ServerTest : public ::testing::Test {
 protected:
  // What the next Detect job throws from its start hook.
  enum class Throw { kNothing, kStdException, kInt, kBadAlloc };

  // Starts a server with `config` adjusted for the test (free ports, the
  // hooks above) and, when `wait_serving`, waits for health SERVING.
  void StartServer(ServerConfig config = DefaultConfig(),
                   bool wait_serving = true);
  void TearDown() override;

  // Concurrency 2, queue 4.
  static ServerConfig DefaultConfig();

  grpc::Status Detect(
      const v1::DetectRequest& request, v1::DetectResponse* response,
      std::chrono::milliseconds deadline =
          std::chrono::duration_cast<std::chrono::milliseconds>(kCallTimeout));
  // Detect on its own thread.
  std::future<grpc::Status> DetectAsync(
      v1::DetectRequest request,
      std::chrono::milliseconds deadline =
          std::chrono::duration_cast<std::chrono::milliseconds>(kCallTimeout));

  // Closes gate_, sends `request` with Detect on its own thread and waits
  // until its job holds at the gate (one more gate_.entered(); a test
  // failure when that does not happen within kCallTimeout).
  std::future<grpc::Status> StartHeldDetect(const v1::DetectRequest& request);

  // The body of /metrics (empty, with a test failure, when it fails).
  std::string Scrape();
  // grpc_server_handled_total for `method` and `code` in `text`; -1 when
  // absent.
  static double Handled(const std::string& text, const std::string& method,
                        const std::string& code);

  void ThrowInNextJob(Throw what) { throw_next_.store(what); }

  // Segment and SegmentIncremental calls gRPC has told the server were
  // cancelled so far; from then on their jobs' checks see it.
  int stream_cancels() const { return stream_cancels_.load(); }

  Gate gate_;
  Gate stage_gate_;
  std::unique_ptr<FoveaServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Perception::Stub> stub_;

 private:
  void ThrowIfAsked();

  std::atomic<Throw> throw_next_{Throw::kNothing};
  std::atomic<int> stream_cancels_{0};
};

}  // namespace fovea::server::testing

#endif  // FOVEA_TESTS_SERVER_SERVER_FIXTURE_H_
