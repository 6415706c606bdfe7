#include "client/fovea_client.h"

#include "absl/time/time.h"
#include "gtest/gtest.h"

namespace fovea::client {
namespace {

TEST(FoveaClientTest, EmptyTargetIsRefused) {
  EXPECT_EQ(FoveaClient::Connect("").status().code(),
            absl::StatusCode::kInvalidArgument);
}

// Port 1 on loopback has no listener here: the call fails quickly with
// UNAVAILABLE, carried over from gRPC with its code.
TEST(FoveaClientTest, NoServerIsUnavailable) {
  absl::StatusOr<std::unique_ptr<FoveaClient>> client =
      FoveaClient::Connect("127.0.0.1:1");
  ASSERT_TRUE(client.ok()) << client.status();
  absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus> health =
      (*client)->Health("", absl::Seconds(5));
  EXPECT_EQ(health.status().code(), absl::StatusCode::kUnavailable)
      << health.status();
  int messages = 0;
  absl::Status segment = (*client)->Segment(
      fovea::v1::SegmentRequest(), absl::Seconds(5),
      [&](const fovea::v1::SegmentResponse&) { ++messages; });
  EXPECT_EQ(segment.code(), absl::StatusCode::kUnavailable) << segment;
  EXPECT_EQ(messages, 0);
}

}  // namespace
}  // namespace fovea::client
