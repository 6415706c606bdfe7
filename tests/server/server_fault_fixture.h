// The fixture of the fault tests (server_fault_test.cc,
// server_malformed_request_test.cc): an in-process FoveaServer without the
// warm-up, one small request per method, and the calls and metric reads
// the tests wait on.

#ifndef FOVEA_TESTS_SERVER_SERVER_FAULT_FIXTURE_H_
#define FOVEA_TESTS_SERVER_SERVER_FAULT_FIXTURE_H_

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <string>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/server.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server::testing {

enum class Method { kDetect, kSegment, kSegmentIncremental };

// "Detect", "Segment" or "SegmentIncremental", as gRPC and the metrics
// name the method.
std::string MethodName(Method method);

// One request per method, all on a 320 x 240 synthetic table scene (small,
// so that a whole call is quick); the streams stop after kStreamObjects
// objects, which keeps their stage boundaries few.
inline constexpr uint32_t kStreamObjects = 2;
struct Requests {
  v1::DetectRequest detect;
  v1::SegmentRequest segment;
  v1::SegmentIncrementalRequest incremental;
};

const Requests& SmallRequests();

// A call's status and, for the streams, every message read.
struct CallResult {
  grpc::Status status;
  std::vector<v1::SegmentResponse> messages;
};

template <typename Reader>
CallResult ReadAll(Reader& reader) {
  CallResult result;
  v1::SegmentResponse message;
  while (reader.Read(&message)) result.messages.push_back(message);
  result.status = reader.Finish();
  return result;
}

// Runs `method` with `requests`' request to the end on `context`.
CallResult RunCall(v1::Perception::Stub& stub, Method method,
                   const Requests& requests, grpc::ClientContext& context);

class FaultTest : public ServerTest {
 protected:
  // DefaultConfig (two workers, queue 4) without the warm-up: the warm-up
  // passes no test hook, so skipping it changes no count, only saves time.
  void Start() {
    ServerConfig config = DefaultConfig();
    config.warm_up = false;
    StartServer(config);
  }

  CallResult Call(
      Method method,
      std::chrono::milliseconds deadline =
          std::chrono::duration_cast<std::chrono::milliseconds>(kCallTimeout)) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + deadline);
    return RunCall(*stub_, method, SmallRequests(), context);
  }

  // `method` on its own thread with the caller's `context`, which must
  // outlive the future's result.
  std::future<CallResult> CallAsync(Method method,
                                    grpc::ClientContext& context) {
    return std::async(std::launch::async, [this, method, &context] {
      return RunCall(*stub_, method, SmallRequests(), context);
    });
  }

  double HandledNow(Method method, const std::string& code) {
    return Handled(Scrape(), MethodName(method), code);
  }

  // Waits until the server counted `count` calls of `method` ending with
  // `code` and no call is in flight (the worker was released).
  bool WaitForHandled(Method method, const std::string& code, double count) {
    return WaitFor(
        [&] {
          const std::string text = Scrape();
          return Handled(text, MethodName(method), code) == count &&
                 MetricValue(text, "fovea_inflight_requests", {}) == 0;
        },
        kCallTimeout);
  }

  // fovea_segment_stops_total of a stream `method` for `reason`.
  double Stops(Method method, const std::string& reason) {
    return MetricValue(Scrape(), "fovea_segment_stops_total",
                       {"grpc_method=\"" + MethodName(method) + "\"",
                        "reason=\"" + reason + "\""})
        .value_or(-1);
  }

  // Runs `method` to the end and returns the stage boundaries it passed
  // (-1, with a test failure, when the call fails).
  int CountBoundaries(Method method) {
    const int before = stage_gate_.entered();
    const CallResult result = Call(method);
    EXPECT_TRUE(result.status.ok())
        << MethodName(method) << ": " << result.status.error_message();
    return result.status.ok() ? stage_gate_.entered() - before : -1;
  }
};

}  // namespace fovea::server::testing

#endif  // FOVEA_TESTS_SERVER_SERVER_FAULT_FIXTURE_H_
