// Faults end to end: an in-process FoveaServer on loopback, a real gRPC
// channel, and the server's test hooks to put each fault at a chosen point
// of a job: a client that cancels mid-stream.
// Every wait is bounded and waits for a fact (a gate count, a metric, a
// client's status), never for a duration to pass.

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/synth/synth_scene.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/convert.h"
#include "server/server.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::kCallTimeout;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::WaitFor;

enum class Method { kDetect, kSegment, kSegmentIncremental };

std::string MethodName(Method method) {
  switch (method) {
    case Method::kDetect:
      return "Detect";
    case Method::kSegment:
      return "Segment";
    case Method::kSegmentIncremental:
      break;
  }
  return "SegmentIncremental";
}

// A 320 x 240 synthetic table scene: small, so that a whole call is quick.
v1::Frame SmallFrame() {
  synth::SceneSpec spec = synth::RandomSceneSpec(3, {});
  spec.width = 320;
  spec.height = 240;
  spec.intrinsics = {262.5, 262.5, 159.5, 119.5};
  const synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, 3);
  return ToProtoFrame(scene.frame.frame, DepthEncoding::k32FC1);
}

// One request per method, all on SmallFrame(); the streams stop after
// kStreamObjects objects, which keeps their stage boundaries few.
constexpr uint32_t kStreamObjects = 2;
struct Requests {
  v1::DetectRequest detect;
  v1::SegmentRequest segment;
  v1::SegmentIncrementalRequest incremental;
};

const Requests& SmallRequests() {
  static const Requests* const requests = [] {
    auto* made = new Requests;
    const v1::Frame frame = SmallFrame();
    *made->detect.mutable_frame() = frame;
    *made->segment.mutable_frame() = frame;
    made->segment.set_max_objects(kStreamObjects);
    *made->incremental.mutable_frame() = frame;
    made->incremental.set_max_objects(kStreamObjects);
    return made;
  }();
  return *requests;
}

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
                   const Requests& requests, grpc::ClientContext& context) {
  switch (method) {
    case Method::kDetect: {
      CallResult result;
      v1::DetectResponse response;
      result.status = stub.Detect(&context, requests.detect, &response);
      return result;
    }
    case Method::kSegment:
      return ReadAll(*stub.Segment(&context, requests.segment));
    case Method::kSegmentIncremental:
      break;
  }
  return ReadAll(*stub.SegmentIncremental(&context, requests.incremental));
}

// The server's copy of a deadline is re-based on the request's arrival, a
// loopback transit later than the client's. Tests that need the server's
// own deadline check to decide (DEADLINE_EXCEEDED rather than the
// client's cancellation, CANCELLED) hold the job until the client's
// deadline plus this margin has passed.
constexpr auto kServerDeadlineMargin = std::chrono::milliseconds(300);

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

// ------------------------------------------------- cancel mid-stream

class CancelMidStreamTest : public FaultTest,
                            public ::testing::WithParamInterface<Method> {};

// The job is held at the middle stage boundary of the stream while the
// client cancels: once released it must stop at that boundary (one more
// at most), end CANCELLED and free its worker.
TEST_P(CancelMidStreamTest, JobStopsWithinOneBoundaryAndServerGoesOn) {
  const Method method = GetParam();
  Start();
  const int total = CountBoundaries(method);
  ASSERT_GE(total, 4);
  const double cancelled = HandledNow(method, "Canceled");
  const double stops_before = Stops(method, "cancelled");
  const int start = stage_gate_.entered();
  const int k = total / 2;
  stage_gate_.CloseAtPass(start + k);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  std::future<CallResult> call = CallAsync(method, context);
  ASSERT_TRUE(WaitFor([&] { return stage_gate_.entered() == start + k; },
                      kCallTimeout));
  context.TryCancel();
  const CallResult ended = call.get();
  EXPECT_EQ(ended.status.error_code(), grpc::StatusCode::CANCELLED);
  // The cancellation reaches the server asynchronously: release the job
  // once gRPC has told the server.
  ASSERT_TRUE(WaitFor([&] { return stream_cancels() == 1; }, kCallTimeout));
  stage_gate_.Open();

  ASSERT_TRUE(WaitForHandled(method, "Canceled", cancelled + 1));
  // Within one step: the check at the very boundary where it was held.
  EXPECT_EQ(stage_gate_.entered(), start + k)
      << "held at boundary " << k << " of " << total;
  EXPECT_EQ(Stops(method, "cancelled"), stops_before + 1);
  const CallResult next = Call(method);
  EXPECT_TRUE(next.status.ok()) << next.status.error_message();
}

INSTANTIATE_TEST_SUITE_P(Streams, CancelMidStreamTest,
                         ::testing::Values(Method::kSegment,
                                           Method::kSegmentIncremental),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           return MethodName(info.param);
                         });

}  // namespace
}  // namespace fovea::server
