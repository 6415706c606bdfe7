// End to end against hostile-but-well-formed requests: each one gets a
// status, never a crash or a hang, and the server goes on serving.

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::testing::AnyOf;
using ::testing::Eq;
using ::testing::HasSubstr;

// A good request with SH saliency (the operator whose grid hostile
// geometry used to blow up).
v1::DetectRequest ShRequest() {
  v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  request.mutable_options()->add_saliency()->set_op(v1::SH);
  return request;
}

class HostileRequestTest : public ServerTest {
 protected:
  // The server still answers a good request.
  void ExpectStillServing() {
    v1::DetectResponse response;
    const grpc::Status status = Detect(ShRequest(), &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_GT(response.points_size(), 0);
  }
};

// Overwrites 32FC1 depth pixel (u, v) of `request` with `metres`.
void SetDepth(v1::DetectRequest& request, int u, int v, float metres) {
  v1::Image& depth = *request.mutable_frame()->mutable_depth();
  ASSERT_EQ(depth.encoding(), "32FC1");
  std::memcpy(depth.mutable_data()->data() +
                  static_cast<size_t>(v) * depth.step() + u * sizeof(float),
              &metres, sizeof(float));
}

TEST_F(HostileRequestTest, TinyFocalLengthIsInvalidArgumentNamingIt) {
  StartServer();
  v1::DetectRequest request = ShRequest();
  request.mutable_frame()->mutable_intrinsics()->set_fx(1e-5);
  v1::DetectResponse response;
  const grpc::Status status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("frame.intrinsics.fx"));
  ExpectStillServing();
}

TEST_F(HostileRequestTest, NonFiniteIntrinsicsAreInvalidArgumentNamingThem) {
  StartServer();
  const double kBad[] = {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity()};
  for (const char* field : {"fx", "fy", "cx", "cy"}) {
    for (const double value : kBad) {
      v1::DetectRequest request = ShRequest();
      v1::Intrinsics& intrinsics =
          *request.mutable_frame()->mutable_intrinsics();
      const std::string name = field;
      if (name == "fx") intrinsics.set_fx(value);
      if (name == "fy") intrinsics.set_fy(value);
      if (name == "cx") intrinsics.set_cx(value);
      if (name == "cy") intrinsics.set_cy(value);
      v1::DetectResponse response;
      const grpc::Status status = Detect(request, &response);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << field << " = " << value;
      EXPECT_THAT(status.error_message(), HasSubstr("frame.intrinsics." + name))
          << field << " = " << value;
    }
  }
  ExpectStillServing();
}

// A few pixels at 3e38 m (finite floats, far beyond any sensor) among a
// normal scene, and a few at 99 m (legal, but far from the rest).
TEST_F(HostileRequestTest, ExtremeDepthPixelsGetAStatusAndServerGoesOn) {
  StartServer();
  for (const float metres : {3e38f, 99.0f}) {
    v1::DetectRequest request = ShRequest();
    const int width = static_cast<int>(request.frame().depth().width());
    const int height = static_cast<int>(request.frame().depth().height());
    for (int i = 0; i < 16; ++i) {
      SetDepth(request, (i * 37) % width, (i * 29 + height / 3) % height,
               metres);
    }
    SetDepth(request, width / 2, height / 2, metres);
    v1::DetectResponse response;
    const auto start = std::chrono::steady_clock::now();
    const grpc::Status status = Detect(request, &response);
    // OK, or a clean refusal naming the reason; never INTERNAL, UNKNOWN
    // (an escaped exception) or a deadline (a runaway computation).
    EXPECT_THAT(
        status.error_code(),
        AnyOf(Eq(grpc::StatusCode::OK), Eq(grpc::StatusCode::INVALID_ARGUMENT),
              Eq(grpc::StatusCode::NOT_FOUND)))
        << metres << " m: " << status.error_message();
    RecordProperty(
        metres > 1e30f ? "ms_3e38" : "ms_99",
        static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::steady_clock::now() - start)
                             .count()));
  }
  ExpectStillServing();
}

TEST_F(HostileRequestTest, HundredThousandRepeatedOperatorsAreRefusedQuickly) {
  StartServer();
  v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  constexpr int kRepeats = 100000;
  for (int i = 0; i < kRepeats; ++i) {
    request.mutable_options()->add_saliency()->set_op(v1::PH);
  }
  const auto start = std::chrono::steady_clock::now();
  v1::DetectResponse response;
  // A server computing PH 100000 times would run into this deadline.
  const grpc::Status status =
      Detect(request, &response, std::chrono::milliseconds(10000));
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("'ph'"));
  EXPECT_THAT(status.error_message(), HasSubstr("more than once"));
  EXPECT_LT(elapsed, std::chrono::seconds(2));
  ExpectStillServing();
}

// Anything a job throws outside core (decoding, conversion, hooks) ends
// the call with INTERNAL; the worker and the process live on.
TEST_F(HostileRequestTest, ExceptionInAJobIsInternalAndServerGoesOn) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;  // both throws hit the same worker
  StartServer(config);
  const std::string before = Scrape();
  v1::DetectResponse response;

  ThrowInNextJob(Throw::kStdException);
  grpc::Status status = Detect(ShRequest(), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_THAT(status.error_message(), HasSubstr("thrown on purpose"));

  ThrowInNextJob(Throw::kInt);
  status = Detect(ShRequest(), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_THAT(status.error_message(), HasSubstr("exception"));

  ExpectStillServing();
  const std::string after = Scrape();
  EXPECT_EQ(Handled(after, "Detect", "Internal"),
            Handled(before, "Detect", "Internal") + 2);
  EXPECT_EQ(MetricValue(after, "fovea_inflight_requests", {}), 0);
}

}  // namespace
}  // namespace fovea::server
