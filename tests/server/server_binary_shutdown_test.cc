// The fovea-server executable on SIGTERM: a clean exit (code 0) when idle,
// with calls in flight, with streams that complete within the grace period
// and with streams stuck past it. Starting and stopping the process is in
// server_process.h.

#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gtest/gtest.h"
#include "tests/server/server_process.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::ExpectCleanExitOnSigterm;
using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::HttpGet;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerProcess;
using ::fovea::server::testing::StartServing;
using ::fovea::server::testing::WaitExit;
using ::fovea::server::testing::WaitFor;

TEST(ServerBinaryTest, ExitsZeroOnSigtermAfterServing) {
  const ServerProcess server =
      StartServing({"--concurrency=1", "--grace_period_s=5"});
  ASSERT_GT(server.pid, 0);
  ExpectCleanExitOnSigterm(server.pid);
}

// Several Detects at once on one worker, so that some are computing or
// queued when SIGTERM arrives: each ends OK (finished within the grace
// period) or UNAVAILABLE / CANCELLED (refused or cut off by the shutdown),
// never another error, and the process exits 0.
TEST(ServerBinaryTest, SigtermWithCallsInFlightLetsThemEndAndExitsZero) {
  constexpr int kCalls = 12;
  const ServerProcess server =
      StartServing({"--concurrency=1", "--queue=" + std::to_string(kCalls),
                    "--grace_period_s=20", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  auto channel =
      grpc::CreateChannel(server.target, grpc::InsecureChannelCredentials());
  auto stub = v1::Perception::NewStub(channel);
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < kCalls; ++i) {
    calls.push_back(std::async(std::launch::async, [&stub, &request] {
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() +
                           std::chrono::seconds(60));
      v1::DetectResponse response;
      return stub->Detect(&context, request, &response);
    }));
  }
  // Signal once the server holds several calls (computing or queued).
  double inflight = 0;
  const bool busy = WaitFor(
      [&] {
        const std::optional<std::string> text =
            HttpGet(server.metrics_port, "/metrics");
        inflight =
            text.has_value()
                ? MetricValue(*text, "fovea_inflight_requests", {}).value_or(0)
                : 0;
        return inflight >= 2;
      },
      std::chrono::seconds(30));
  EXPECT_TRUE(busy) << "the server never held 2 calls at once";
  ExpectCleanExitOnSigterm(server.pid);

  int ok = 0;
  for (std::future<grpc::Status>& call : calls) {
    const grpc::Status status = call.get();
    if (status.ok()) ++ok;
    EXPECT_TRUE(status.ok() ||
                status.error_code() == grpc::StatusCode::UNAVAILABLE ||
                status.error_code() == grpc::StatusCode::CANCELLED)
        << status.error_code() << ": " << status.error_message();
  }
  // The calls in flight at the signal had 20 s to finish: they did.
  EXPECT_GE(ok, static_cast<int>(inflight));
  RecordProperty("inflight_at_sigterm", static_cast<int>(inflight));
  RecordProperty("ok", ok);
}

// Streams held in flight at SIGTERM: each client reads nothing until the
// server has begun to shut down, and each message carries a 1 MiB
// request_id over a channel whose HTTP/2 window stays at 64 KiB, so no
// stream can finish (nor its job get past its third message) before the
// signal, whatever the machine's speed.
constexpr size_t kBigRequestIdBytes = 1 << 20;

struct HeldStream {
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientReader<v1::SegmentResponse>> reader;
};

// Opens `count` streams on `server`, alternately Segment and
// SegmentIncremental, and waits until the server holds all of them.
std::vector<HeldStream> OpenHeldStreams(const ServerProcess& server,
                                        v1::Perception::Stub& stub, int count) {
  const v1::Frame frame = MakeSyntheticRequest(3, false).request.frame();
  v1::SegmentRequest segment;
  segment.set_request_id(std::string(kBigRequestIdBytes, 'x'));
  *segment.mutable_frame() = frame;
  v1::SegmentIncrementalRequest incremental;
  incremental.set_request_id(segment.request_id());
  *incremental.mutable_frame() = frame;
  std::vector<HeldStream> streams(count);
  for (int i = 0; i < count; ++i) {
    streams[i].context = std::make_unique<grpc::ClientContext>();
    streams[i].context->set_deadline(std::chrono::system_clock::now() +
                                     std::chrono::seconds(60));
    streams[i].reader =
        i % 2 == 0
            ? stub.Segment(streams[i].context.get(), segment)
            : stub.SegmentIncremental(streams[i].context.get(), incremental);
  }
  EXPECT_TRUE(WaitFor(
      [&] {
        const std::optional<std::string> text =
            HttpGet(server.metrics_port, "/metrics");
        return text.has_value() &&
               MetricValue(*text, "fovea_inflight_requests", {}) == count;
      },
      std::chrono::seconds(30)))
      << "the server never held all " << count << " streams";
  return streams;
}

// How one stream ended.
struct StreamEnd {
  grpc::Status status;
  bool last = false;  // its last message had `last` set
};

// Reads every stream to its end, all at once (a stream queued behind an
// unread one would wait for it otherwise).
std::vector<StreamEnd> ReadAllStreams(std::vector<HeldStream>& streams) {
  std::vector<std::future<StreamEnd>> reads;
  for (HeldStream& stream : streams) {
    reads.push_back(std::async(std::launch::async, [&stream] {
      StreamEnd end;
      v1::SegmentResponse message;
      while (stream.reader->Read(&message)) end.last = message.last();
      end.status = stream.reader->Finish();
      return end;
    }));
  }
  std::vector<StreamEnd> ends;
  for (std::future<StreamEnd>& read : reads) ends.push_back(read.get());
  return ends;
}

// A stub whose channel keeps HTTP/2's initial 64 KiB receive window (no
// BDP probing, which grows it while a client reads).
std::unique_ptr<v1::Perception::Stub> SmallWindowStub(
    const std::string& target) {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  return v1::Perception::NewStub(grpc::CreateCustomChannel(
      target, grpc::InsecureChannelCredentials(), args));
}

// Two streams computing (each blocked writing to its unread client) and
// six queued at SIGTERM, with a grace period long enough: once their
// clients read, every one completes with its last message, and the
// process exits 0. (30 s was not long enough for eight under TSan on a
// loaded machine: four were cancelled.)
TEST(ServerBinaryTest, SigtermWithStreamsInFlightLetsThemCompleteAndExitsZero) {
  constexpr int kStreams = 8;
  const ServerProcess server =
      StartServing({"--concurrency=2", "--queue=" + std::to_string(kStreams),
                    "--grace_period_s=300", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  const auto stub = SmallWindowStub(server.target);
  std::vector<HeldStream> streams = OpenHeldStreams(server, *stub, kStreams);

  ASSERT_EQ(kill(server.pid, SIGTERM), 0);
  // Shutting down: health leaves SERVING (NOT_SERVING while draining, then
  // no answer once the server stops accepting calls).
  EXPECT_TRUE(WaitFor(
      [&] {
        return HealthStatus(
                   grpc::CreateChannel(server.target,
                                       grpc::InsecureChannelCredentials()),
                   "") != "SERVING";
      },
      std::chrono::seconds(30)));
  const std::vector<StreamEnd> ends = ReadAllStreams(streams);
  for (int i = 0; i < kStreams; ++i) {
    EXPECT_TRUE(ends[i].status.ok())
        << "stream " << i << ": " << ends[i].status.error_code() << " "
        << ends[i].status.error_message();
    EXPECT_TRUE(ends[i].last) << "stream " << i;
  }
  const int status = WaitExit(server.pid, std::chrono::seconds(30));
  if (status == -1) {
    kill(server.pid, SIGKILL);
    waitpid(server.pid, nullptr, 0);
  }
  ASSERT_NE(status, -1) << "did not exit within 30 s of the streams' end";
  EXPECT_TRUE(WIFEXITED(status)) << "wait status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// The same streams with a grace period too short for clients that still
// read nothing: the server cancels them, which releases the workers
// blocked writing (and the queued jobs see the cancellation at once); it
// exits 0 while the streams are still unread. Each stream then ends
// CANCELLED or UNAVAILABLE, never another error.
TEST(ServerBinaryTest, SigtermWithStuckStreamsCancelsThemAndExitsZero) {
  constexpr int kStreams = 6;
  const ServerProcess server =
      StartServing({"--concurrency=2", "--queue=" + std::to_string(kStreams),
                    "--grace_period_s=0.5", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  const auto stub = SmallWindowStub(server.target);
  std::vector<HeldStream> streams = OpenHeldStreams(server, *stub, kStreams);

  ExpectCleanExitOnSigterm(server.pid);
  const std::vector<StreamEnd> ends = ReadAllStreams(streams);
  for (int i = 0; i < kStreams; ++i) {
    EXPECT_TRUE(ends[i].status.error_code() == grpc::StatusCode::CANCELLED ||
                ends[i].status.error_code() == grpc::StatusCode::UNAVAILABLE)
        << "stream " << i << ": " << ends[i].status.error_code() << " "
        << ends[i].status.error_message();
    EXPECT_FALSE(ends[i].last) << "stream " << i;
  }
}

}  // namespace
}  // namespace fovea::server
