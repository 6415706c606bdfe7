// Faults end to end while a job runs: an in-process FoveaServer on
// loopback, a real gRPC channel, and the server's test hooks to put each
// fault at a chosen point of a job: a client that cancels mid-stream, a
// deadline that passes at each stage boundary, a client that stops
// reading. Every wait is bounded and waits for a fact (a gate count, a
// metric, a client's status), never for a duration to pass. The fixture,
// FaultTest, is in tests/server/server_fault_fixture.h; requests that are
// not requests are in server_malformed_request_test.cc.

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/server.h"
#include "tests/server/server_fault_fixture.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::CallResult;
using ::fovea::server::testing::FaultTest;
using ::fovea::server::testing::kCallTimeout;
using ::fovea::server::testing::Method;
using ::fovea::server::testing::MethodName;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ReadAll;
using ::fovea::server::testing::Requests;
using ::fovea::server::testing::SmallRequests;
using ::fovea::server::testing::WaitFor;

// The server's copy of a deadline is re-based on the request's arrival, a
// loopback transit later than the client's. Tests that need the server's
// own deadline check to decide (DEADLINE_EXCEEDED rather than the
// client's cancellation, CANCELLED) hold the job until the client's
// deadline plus this margin has passed.
constexpr auto kServerDeadlineMargin = std::chrono::milliseconds(300);

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

// ------------------------------------------- a deadline at every boundary

// The stage boundaries a whole call of each method passes on
// SmallRequests(): Detect 1 after decoding + 3 of core's; Segment and
// SegmentIncremental those of the scene, the seeds and each of
// kStreamObjects objects. DeadlineSweepCoversEveryBoundary checks them, so
// that the sweep below keeps covering every boundary when the pipeline
// changes. SegmentIncremental 10 -> 14 when INC began to hold back pieces
// that rest on nothing (IncOptions::WholeObject): the segmenter grows
// more objects, checking at each growth step, before its first two are
// reported.
constexpr int kDetectBoundaries = 4;
constexpr int kSegmentBoundaries = 11;
constexpr int kIncrementalBoundaries = 14;

int Boundaries(Method method) {
  switch (method) {
    case Method::kDetect:
      return kDetectBoundaries;
    case Method::kSegment:
      return kSegmentBoundaries;
    case Method::kSegmentIncremental:
      break;
  }
  return kIncrementalBoundaries;
}

TEST_F(FaultTest, DeadlineSweepCoversEveryBoundary) {
  Start();
  for (Method method :
       {Method::kDetect, Method::kSegment, Method::kSegmentIncremental}) {
    EXPECT_EQ(CountBoundaries(method), Boundaries(method))
        << MethodName(method) << ": update the sweep's boundary count";
  }
}

// The first deadline tried; doubled while the job cannot reach its
// boundary in time (a loaded machine), up to kLastDeadline.
constexpr auto kFirstDeadline = std::chrono::milliseconds(300);
constexpr auto kLastDeadline = std::chrono::milliseconds(9600);

// (method, k): the deadline passes while the job is held at stage boundary
// k, 1-based; k = 0 while it waits in the queue for a worker.
class DeadlineAtBoundaryTest
    : public FaultTest,
      public ::testing::WithParamInterface<std::tuple<Method, int>> {
 protected:
  // Holds the job at boundary k until its deadline passed for the client
  // (its status says so) and for the server (kServerDeadlineMargin later),
  // then releases it. Retries with a longer deadline while the job cannot
  // reach boundary k in time. On return the call was handled.
  // Waits until `expiry` plus kServerDeadlineMargin has passed, so the
  // server's own copy of the call's deadline has passed too.
  static bool WaitPastServerDeadline(
      std::chrono::system_clock::time_point expiry) {
    return WaitFor(
        [&] {
          return std::chrono::system_clock::now() >
                 expiry + kServerDeadlineMargin;
        },
        kCallTimeout);
  }

  void HoldAtBoundaryPastTheDeadline(Method method, int k) {
    for (auto deadline = kFirstDeadline;; deadline *= 2) {
      ASSERT_LE(deadline, kLastDeadline)
          << "the job never reached boundary " << k << " in time";
      const int start = stage_gate_.entered();
      const double handled = HandledNow(method, "DeadlineExceeded");
      stage_gate_.CloseAtPass(start + k);
      grpc::ClientContext context;
      const auto expiry = std::chrono::system_clock::now() + deadline;
      context.set_deadline(expiry);
      std::future<CallResult> call = CallAsync(method, context);
      EXPECT_EQ(call.get().status.error_code(),
                grpc::StatusCode::DEADLINE_EXCEEDED);
      ASSERT_TRUE(WaitPastServerDeadline(expiry));
      // Now the job is held at k, or it stopped before k because its
      // deadline came first: then try again with a longer one.
      bool held = false;
      ASSERT_TRUE(WaitFor(
          [&] {
            held = stage_gate_.entered() == start + k;
            return held ||
                   MetricValue(Scrape(), "fovea_inflight_requests", {}) == 0;
          },
          kCallTimeout));
      if (!held) {
        stage_gate_.Open();
        continue;
      }
      stage_gate_.Open();
      ASSERT_TRUE(WaitForHandled(method, "DeadlineExceeded", handled + 1));
      EXPECT_LE(stage_gate_.entered(), start + k + 1)
          << "the job went on after boundary " << k;
      RecordProperty("deadline_ms", static_cast<int>(deadline.count()));
      return;
    }
  }

  // Holds a Detect at the start of the only worker's job (gate_) and queues
  // the call; its deadline passes in the queue, then the worker is freed.
  void ExpireInTheQueue(Method method) {
    const double handled = HandledNow(method, "DeadlineExceeded");
    const std::string before = Scrape();
    const int start = stage_gate_.entered();
    std::future<grpc::Status> holder = StartHeldDetect(SmallRequests().detect);
    grpc::ClientContext context;
    const auto expiry = std::chrono::system_clock::now() + kFirstDeadline;
    context.set_deadline(expiry);
    std::future<CallResult> call = CallAsync(method, context);
    ASSERT_TRUE(
        WaitFor([this] { return server_->queued_jobs() == 1; }, kCallTimeout));
    EXPECT_EQ(call.get().status.error_code(),
              grpc::StatusCode::DEADLINE_EXCEEDED);
    ASSERT_TRUE(WaitPastServerDeadline(expiry));
    gate_.Open();
    EXPECT_TRUE(holder.get().ok());
    ASSERT_TRUE(WaitForHandled(method, "DeadlineExceeded", handled + 1));
    // Only the holder was decoded and passed boundaries.
    EXPECT_EQ(stage_gate_.entered(), start + kDetectBoundaries);
    auto decodes = [](const std::string& text) {
      return MetricValue(text, "fovea_stage_duration_seconds_count",
                         {"stage=\"decode\""})
          .value_or(-1);
    };
    EXPECT_EQ(decodes(Scrape()), decodes(before) + 1);
  }
};

TEST_P(DeadlineAtBoundaryTest, JobStopsThereAndServerGoesOn) {
  const auto [method, k] = GetParam();
  ServerConfig config = DefaultConfig();
  config.warm_up = false;
  if (k == 0) config.concurrency = 1;  // one job holds the only worker
  StartServer(config);
  if (k == 0) {
    ExpireInTheQueue(method);
  } else {
    HoldAtBoundaryPastTheDeadline(method, k);
  }
  if (HasFatalFailure()) return;
  const CallResult next = Call(method);
  EXPECT_TRUE(next.status.ok()) << next.status.error_message();
}

std::vector<std::tuple<Method, int>> EveryBoundary() {
  std::vector<std::tuple<Method, int>> cases;
  for (Method method :
       {Method::kDetect, Method::kSegment, Method::kSegmentIncremental}) {
    for (int k = 0; k <= Boundaries(method); ++k) cases.emplace_back(method, k);
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(
    EveryMethod, DeadlineAtBoundaryTest, ::testing::ValuesIn(EveryBoundary()),
    [](const ::testing::TestParamInfo<std::tuple<Method, int>>& info) {
      const int k = std::get<1>(info.param);
      return MethodName(std::get<0>(info.param)) +
             (k == 0 ? std::string("_InTheQueue")
                     : "_AtBoundary" + std::to_string(k));
    });

// ------------------------------------------ a client that stops reading

// How a stalled stream ends.
enum class Ending { kCancel, kDeadline };

// A request_id is echoed in every message of a stream: this many bytes
// make each message far larger than HTTP/2's initial 64 KiB window.
constexpr size_t kBigRequestIdBytes = 1 << 20;
// Progress (stage boundaries, messages written) unchanged for this many
// polls in a row (WaitFor polls every few ms) counts as stalled.
constexpr int kStablePolls = 40;
// The stalled call's deadline when Ending::kDeadline.
constexpr auto kStalledDeadline = std::chrono::seconds(2);

// SmallRequests() with every object and a kBigRequestIdBytes request_id.
Requests BigMessageRequests() {
  Requests requests = SmallRequests();
  const std::string big_id(kBigRequestIdBytes, 'x');
  requests.segment.set_request_id(big_id);
  requests.segment.set_max_objects(0);
  requests.incremental.set_request_id(big_id);
  requests.incremental.set_max_objects(0);
  return requests;
}

// A stub on a channel of its own to `port` whose HTTP/2 receive window
// stays at its initial 64 KiB: BDP probing, which grows the window while
// a client reads quickly, is off (on a default channel the window grows
// to megabytes).
std::unique_ptr<v1::Perception::Stub> SmallWindowStub(int port) {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  return v1::Perception::NewStub(
      grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port),
                                grpc::InsecureChannelCredentials(), args));
}

class StalledReaderTest
    : public FaultTest,
      public ::testing::WithParamInterface<std::tuple<Method, Ending>> {
 protected:
  double Sent(Method method) {
    return MetricValue(Scrape(), "grpc_server_msg_sent_total",
                       {"grpc_method=\"" + MethodName(method) + "\""})
        .value_or(-1);
  }

  static std::unique_ptr<grpc::ClientReader<v1::SegmentResponse>> Open(
      v1::Perception::Stub& stub, Method method, const Requests& requests,
      grpc::ClientContext& context) {
    return method == Method::kSegment
               ? stub.Segment(&context, requests.segment)
               : stub.SegmentIncremental(&context, requests.incremental);
  }
};

// What bounds the memory of a stream whose client reads nothing: the
// reactor keeps at most 2 MiB of unwritten messages (at least one, at most
// 16) plus the one being written, and gRPC sends that one only as far as the
// client's HTTP/2 flow-control window lets it. The window is the client's: 64
// KiB at first, grown by BDP probing only while the client reads. The job
// blocks in its next Send until the client reads, cancels or runs out of
// time. Here each message is > 1 MiB and the window 64 KiB, so not even
// the first message is written whole: the job must stop partway, holding
// its worker while the other worker still serves, and be released when
// the call ends.
TEST_P(StalledReaderTest, JobBlocksPartwayAndIsReleasedWhenTheCallEnds) {
  const auto [method, ending] = GetParam();
  // The test ends the stalled call itself (cancel or deadline): the
  // server's stall timeout must not end it first, however slow the build
  // (its default 5 s did, under TSan beside a build, 2026-12-06).
  ServerConfig config = DefaultConfig();
  config.stream_stall_timeout_s = 600.0;
  StartServer(config);
  const Requests requests = BigMessageRequests();
  const std::unique_ptr<v1::Perception::Stub> stub =
      SmallWindowStub(server_->port());

  // A client that reads: how many messages and boundaries the whole call
  // makes.
  int start = stage_gate_.entered();
  double sent_before = Sent(method);
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
    const CallResult full = ReadAll(*Open(*stub, method, requests, context));
    ASSERT_TRUE(full.status.ok()) << full.status.error_message();
    // One being written and two queued: a fourth must wait.
    ASSERT_GE(full.messages.size(), 4u) << "too few messages to fill up";
  }
  const int total_boundaries = stage_gate_.entered() - start;
  const double total_messages = Sent(method) - sent_before;

  // A client that reads nothing.
  const double cancelled = HandledNow(method, "Canceled");
  const double expired = HandledNow(method, "DeadlineExceeded");
  start = stage_gate_.entered();
  sent_before = Sent(method);
  grpc::ClientContext context;
  context.set_deadline(
      std::chrono::system_clock::now() +
      (ending == Ending::kDeadline ? kStalledDeadline : kCallTimeout));
  auto reader = Open(*stub, method, requests, context);
  int last_entered = -1;
  double last_sent = -1;
  int stable = 0;
  ASSERT_TRUE(WaitFor(
      [&] {
        const int entered = stage_gate_.entered();
        const double sent = Sent(method);
        stable = entered > start && entered == last_entered && sent == last_sent
                     ? stable + 1
                     : 0;
        last_entered = entered;
        last_sent = sent;
        return stable >= kStablePolls;
      },
      kCallTimeout));
  const int stalled_boundaries = last_entered - start;
  const double stalled_messages = last_sent - sent_before;
  RecordProperty("boundaries_of_a_whole_call", total_boundaries);
  RecordProperty("boundaries_before_the_stall", stalled_boundaries);
  RecordProperty("messages_of_a_whole_call", static_cast<int>(total_messages));
  RecordProperty("messages_written_before_the_stall",
                 static_cast<int>(stalled_messages));
  EXPECT_LT(stalled_boundaries, total_boundaries);
  EXPECT_EQ(stalled_messages, 0);

  if (ending == Ending::kCancel) {
    // Still in flight, and the other worker still serves.
    EXPECT_EQ(MetricValue(Scrape(), "fovea_inflight_requests", {}), 1);
    const CallResult detect = Call(Method::kDetect);
    EXPECT_TRUE(detect.status.ok()) << detect.status.error_message();
    EXPECT_EQ(stage_gate_.entered(),
              start + stalled_boundaries + kDetectBoundaries)
        << "the stalled job went on";
    context.TryCancel();
    ASSERT_TRUE(WaitForHandled(method, "Canceled", cancelled + 1));
  } else {
    // The server records DEADLINE_EXCEEDED when its own copy of the
    // deadline passed first; the client's RST_STREAM on expiry can reach
    // it a moment before (that copy is re-based on the request's arrival),
    // and then the server saw a cancellation.
    ASSERT_TRUE(WaitFor(
        [&] {
          const std::string text = Scrape();
          return Handled(text, MethodName(method), "DeadlineExceeded") +
                         Handled(text, MethodName(method), "Canceled") ==
                     expired + cancelled + 1 &&
                 MetricValue(text, "fovea_inflight_requests", {}) == 0;
        },
        kCallTimeout));
  }
  // Released from its Send, the job stopped without another boundary.
  EXPECT_EQ(stage_gate_.entered(),
            start + stalled_boundaries +
                (ending == Ending::kCancel ? kDetectBoundaries : 0));
  v1::SegmentResponse message;
  while (reader->Read(&message)) {
  }
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), ending == Ending::kCancel
                                     ? grpc::StatusCode::CANCELLED
                                     : grpc::StatusCode::DEADLINE_EXCEEDED);
  const CallResult next = Call(method);
  EXPECT_TRUE(next.status.ok()) << next.status.error_message();
}

// A job that made all its messages before the client read them has
// finished, but its call has not: the last messages still wait to be
// written. When the client then leaves, the call ends CANCELLED for the
// server too (its record says what the client got), not OK.
TEST_F(FaultTest, StreamWhoseClientLeavesBeforeTheLastMessageIsNotRecordedOk) {
  Start();
  Requests requests = BigMessageRequests();
  requests.segment.set_max_objects(1);  // 3 messages: all fit the queue
  const std::unique_ptr<v1::Perception::Stub> stub =
      SmallWindowStub(server_->port());
  const std::string before = Scrape();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  auto reader = stub->Segment(&context, requests.segment);
  // The job is done once it recorded its stop reason.
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricValue(
                   Scrape(), "fovea_segment_stops_total",
                   {"grpc_method=\"Segment\"", "reason=\"max_objects\""}) ==
               MetricValue(
                   before, "fovea_segment_stops_total",
                   {"grpc_method=\"Segment\"", "reason=\"max_objects\""})
                       .value_or(-1) +
                   1;
      },
      kCallTimeout));
  EXPECT_EQ(MetricValue(Scrape(), "fovea_inflight_requests", {}), 1)
      << "the call ended before its messages were read";
  context.TryCancel();
  ASSERT_TRUE(WaitForHandled(Method::kSegment, "Canceled",
                             Handled(before, "Segment", "Canceled") + 1));
  EXPECT_EQ(Handled(Scrape(), "Segment", "OK"),
            Handled(before, "Segment", "OK"));
  v1::SegmentResponse message;
  while (reader->Read(&message)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
}

// A finished job's last messages wait for the client without its worker:
// with one worker, a Detect is answered while a stream whose client reads
// nothing still holds its last messages (it waited for the stall timeout
// before), and the stall watch then cancels that stream.
TEST_F(FaultTest, LastMessagesWaitingForTheClientHoldNoWorker) {
  ServerConfig config = DefaultConfig();
  config.warm_up = false;
  config.concurrency = 1;
  config.stream_stall_timeout_s = 6.0;
  StartServer(config);
  // 3 messages of 256 KiB: each over the client's 64 KiB window, all
  // within the reactor's 2 MiB of unwritten messages (the job is done).
  Requests requests = SmallRequests();
  requests.segment.set_request_id(std::string(256 << 10, 'x'));
  requests.segment.set_max_objects(1);
  const std::unique_ptr<v1::Perception::Stub> stub =
      SmallWindowStub(server_->port());
  const std::string before = Scrape();
  const auto stops = [](const std::string& text) {
    return MetricValue(text, "fovea_segment_stops_total",
                       {"grpc_method=\"Segment\"", "reason=\"max_objects\""})
        .value_or(0);
  };
  const auto stalled = [](const std::string& text) {
    return MetricValue(text, "fovea_calls_shed_total",
                       {"reason=\"stalled_stream\""})
        .value_or(0);
  };
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  auto reader = stub->Segment(&context, requests.segment);
  ASSERT_TRUE(WaitFor([&] { return stops(Scrape()) == stops(before) + 1; },
                      kCallTimeout));
  EXPECT_EQ(MetricValue(Scrape(), "fovea_inflight_requests", {}), 1);
  // Half the stall timeout: the only worker must be free to serve it.
  const CallResult detect = Call(Method::kDetect, std::chrono::seconds(3));
  EXPECT_TRUE(detect.status.ok()) << detect.status.error_message();
  ASSERT_TRUE(WaitForHandled(Method::kSegment, "Canceled",
                             Handled(before, "Segment", "Canceled") + 1));
  EXPECT_EQ(stalled(Scrape()), stalled(before) + 1);
  v1::SegmentResponse message;
  while (reader->Read(&message)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
}

INSTANTIATE_TEST_SUITE_P(
    Streams, StalledReaderTest,
    ::testing::Combine(::testing::Values(Method::kSegment,
                                         Method::kSegmentIncremental),
                       ::testing::Values(Ending::kCancel, Ending::kDeadline)),
    [](const ::testing::TestParamInfo<std::tuple<Method, Ending>>& info) {
      return MethodName(std::get<0>(info.param)) +
             (std::get<1>(info.param) == Ending::kCancel ? "_Cancelled"
                                                         : "_DeadlinePassed");
    });

}  // namespace
}  // namespace fovea::server
