// Faults end to end in the request itself: bytes that are not a protobuf
// and a frame that claims an enormous size, sent to an in-process
// FoveaServer over a real gRPC channel (FaultTest,
// tests/server/server_fault_fixture.h). Each is refused saying what is
// wrong, and the server goes on.

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/server_fault_fixture.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::FaultTest;
using ::fovea::server::testing::kCallTimeout;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::Method;
using ::fovea::server::testing::MethodName;
using ::fovea::server::testing::MetricIncrease;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::SmallRequests;
using ::testing::HasSubstr;

// -------------------------------------------------- malformed protobuf

// The status of a call of `method` (e.g. "/fovea.v1.Perception/Detect")
// whose one request message is `bytes`, and the number of messages
// answered. Sent with the generic stub, which does not serialise.
struct RawCallResult {
  grpc::Status status;
  int messages = 0;
};

RawCallResult CallWithBytes(const std::shared_ptr<grpc::Channel>& channel,
                            const std::string& method,
                            const std::string& bytes) {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue queue;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
      stub.PrepareCall(&context, method, &queue);
  // Each operation is started, then its tag awaited before the next.
  auto await = [&queue](intptr_t tag) {
    void* got = nullptr;
    bool ok = false;
    EXPECT_TRUE(queue.Next(&got, &ok));
    EXPECT_EQ(reinterpret_cast<intptr_t>(got), tag);
    return ok;
  };
  RawCallResult result;
  call->StartCall(reinterpret_cast<void*>(1));
  await(1);
  grpc::Slice slice(bytes);
  call->WriteLast(grpc::ByteBuffer(&slice, 1), grpc::WriteOptions(),
                  reinterpret_cast<void*>(2));
  await(2);  // fails when the server ended the call first: fine
  grpc::ByteBuffer response;
  while (true) {
    call->Read(&response, reinterpret_cast<void*>(3));
    if (!await(3)) break;
    ++result.messages;
  }
  call->Finish(&result.status, reinterpret_cast<void*>(4));
  await(4);
  queue.Shutdown();
  void* tag = nullptr;
  bool ok = false;
  while (queue.Next(&tag, &ok)) {
  }
  return result;
}

// Bytes that no protobuf parser accepts, each as the whole request, and
// what the answer must say.
struct Malformed {
  const char* name;
  std::string bytes;
  const char* says;
};

std::vector<Malformed> MalformedRequests() {
  return {
      // Field 1, varint, whose bytes all say "more follows".
      {"truncated varint", std::string("\x08\xff\xff\xff", 4),
       "field request_id (1) has a truncated varint"},
      // Field 1 with wire type 7, which does not exist.
      {"wire type 7", std::string("\x0f\x01\x02\x03", 4), "has wire type 7"},
      // Field 2 (the frame), length-delimited, claiming 2^31 bytes.
      {"2 GiB length", std::string("\x12\x80\x80\x80\x80\x08\x0a\x00", 8),
       "(2) declares 2147483648 bytes but 2 follow"},
      // Field 2 (the frame) cut short: 5 bytes claimed, 2 given.
      {"short sub-message", std::string("\x12\x05\x0a\x00", 4),
       "(2) declares 5 bytes but 2 follow"},
      // request_id (a proto3 string) that is not UTF-8.
      {"bad UTF-8", std::string("\x0a\x02\xc3\x28", 4), "is not valid UTF-8"},
  };
}

// Each method parses its request's body itself: a malformed one is
// INVALID_ARGUMENT saying what is wrong, counted like any call, and the
// server goes on. (gRPC's own deserialisation answered UNIMPLEMENTED with
// no message, before any of the server's code ran.)
TEST_F(FaultTest,
       MalformedProtobufIsInvalidArgumentSayingWhereAndServerGoesOn) {
  Start();
  for (Method method :
       {Method::kDetect, Method::kSegment, Method::kSegmentIncremental}) {
    const std::string path = "/fovea.v1.Perception/" + MethodName(method);
    const std::vector<std::string> labels = {
        "grpc_method=\"" + MethodName(method) + "\"",
        "grpc_code=\"InvalidArgument\""};
    const double before =
        MetricValue(Scrape(), "grpc_server_handled_total", labels).value_or(0);
    for (const Malformed& malformed : MalformedRequests()) {
      const RawCallResult result =
          CallWithBytes(channel_, path, malformed.bytes);
      EXPECT_EQ(result.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << path << ", " << malformed.name << ": "
          << result.status.error_message();
      EXPECT_THAT(result.status.error_message(),
                  AllOf(HasSubstr("request body is not a valid fovea.v1."),
                        HasSubstr(malformed.says)))
          << path << ", " << malformed.name;
      EXPECT_EQ(result.messages, 0) << path << ", " << malformed.name;
    }
    EXPECT_EQ(
        MetricValue(Scrape(), "grpc_server_handled_total", labels).value_or(0) -
            before,
        static_cast<double>(MalformedRequests().size()))
        << path;
    // The same path with a good request's bytes works.
    std::string good;
    ASSERT_TRUE(method == Method::kDetect
                    ? SmallRequests().detect.SerializeToString(&good)
                : method == Method::kSegment
                    ? SmallRequests().segment.SerializeToString(&good)
                    : SmallRequests().incremental.SerializeToString(&good));
    const RawCallResult result = CallWithBytes(channel_, path, good);
    EXPECT_TRUE(result.status.ok())
        << path << ": " << result.status.error_message();
    EXPECT_GE(result.messages, 1) << path;
  }
  // A string deep in the request names its whole path.
  v1::DetectRequest request = SmallRequests().detect;
  request.mutable_frame()->set_frame_id("\xc3\x28");
  std::string bytes = request.SerializePartialAsString();
  const RawCallResult deep =
      CallWithBytes(channel_, "/fovea.v1.Perception/Detect", bytes);
  EXPECT_EQ(deep.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(deep.status.error_message(),
              HasSubstr("field frame (2).frame_id ("));
  EXPECT_EQ(MetricValue(Scrape(), "fovea_inflight_requests", {}), 0);
}

// Under overload a refusal costs next to nothing: while the work queue is
// full, a call is refused busy before its body is parsed (a malformed one
// too: it is never read), and counted as shed; once there is room, the
// same bytes are parsed and named as malformed.
TEST_F(ServerTest, AFullServerRefusesBeforeParsingTheBody) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 0;
  StartServer(config);
  const std::string before = Scrape();  // the binary's tests share metrics
  std::future<grpc::Status> running =
      StartHeldDetect(MakeSyntheticRequest(1, false).request);
  ASSERT_EQ(gate_.entered(), 1);
  const std::string malformed = MalformedRequests()[0].bytes;
  for (Method method :
       {Method::kDetect, Method::kSegment, Method::kSegmentIncremental}) {
    const std::string path = "/fovea.v1.Perception/" + MethodName(method);
    const RawCallResult refused = CallWithBytes(channel_, path, malformed);
    EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
        << path << ": " << refused.status.error_message();
    EXPECT_THAT(refused.status.error_message(), HasSubstr("server busy"));
  }
  EXPECT_EQ(MetricIncrease(before, Scrape(), "fovea_calls_shed_total",
                           {"reason=\"busy\""}),
            3);
  gate_.Open();
  ASSERT_TRUE(running.get().ok());
  // The answer can come before its job leaves the only worker, and until
  // then the server is still full.
  ASSERT_TRUE(testing::WaitFor([this] { return server_->running_jobs() == 0; },
                               kCallTimeout));
  const RawCallResult parsed =
      CallWithBytes(channel_, "/fovea.v1.Perception/Detect", malformed);
  EXPECT_EQ(parsed.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

// Consistent encodings but 4e9 x 4e9 pixels over a few bytes of data:
// refused naming the field before anything the size of the claim is
// allocated (that would fail with RESOURCE_EXHAUSTED, or worse).
TEST_F(FaultTest, FrameClaimingEnormousSizeIsInvalidArgumentNamingIt) {
  Start();
  constexpr uint32_t kHuge = 4000000000u;
  v1::DetectRequest request = SmallRequests().detect;
  for (v1::Image* image : {request.mutable_frame()->mutable_color(),
                           request.mutable_frame()->mutable_depth()}) {
    image->set_width(kHuge);
    image->set_height(kHuge);
    image->set_step(kHuge);
    image->set_data("tiny");
  }
  v1::DetectResponse response;
  grpc::Status status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("frame.color.width"));

  // Only the height enormous: the step fits, the rows do not.
  request = SmallRequests().detect;
  request.mutable_frame()->mutable_depth()->set_height(kHuge);
  status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("frame.depth.height"));

  EXPECT_TRUE(Call(Method::kDetect).status.ok());
}

}  // namespace
}  // namespace fovea::server
