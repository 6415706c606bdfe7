// End to end, operations: capabilities, health, /metrics under slow
// clients, connection age (ServerTest, tests/server/server_fixture.h).

#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <memory>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "core/base/strings.h"
#include "core/pipeline/detect.h"
#include "core/synth/room.h"
#include "core/synth/synth_scene.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/capabilities.h"
#include "server/convert.h"
#include "server/server.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::kCallTimeout;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::SyntheticRequest;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

TEST_F(ServerTest, CapabilitiesReportWhatCoreImplements) {
  StartServer();
  grpc::ClientContext context;
  v1::GetCapabilitiesResponse capabilities;
  ASSERT_TRUE(stub_
                  ->GetCapabilities(&context, v1::GetCapabilitiesRequest(),
                                    &capabilities)
                  .ok());
  EXPECT_EQ(capabilities.server_version(), ServerVersion());
  EXPECT_THAT(capabilities.saliency_operators(),
              ::testing::UnorderedElementsAre(
                  v1::SALIENCY_OPERATOR_PH, v1::SALIENCY_OPERATOR_SH,
                  v1::SALIENCY_OPERATOR_RSO, v1::SALIENCY_OPERATOR_SYM3D,
                  v1::SALIENCY_OPERATOR_ITTI, v1::SALIENCY_OPERATOR_HAREL,
                  v1::SALIENCY_OPERATOR_HOU, v1::SALIENCY_OPERATOR_KOOTSTRA,
                  v1::SALIENCY_OPERATOR_TARGET_COLOR,
                  v1::SALIENCY_OPERATOR_LOCATION_PRIOR));
  EXPECT_THAT(capabilities.extractions(),
              ::testing::UnorderedElementsAre(
                  v1::EXTRACTION_MSR, v1::EXTRACTION_WTA, v1::EXTRACTION_TJ));
  EXPECT_THAT(capabilities.pyramids(),
              ::testing::UnorderedElementsAre(
                  v1::PYRAMID_NONE, v1::PYRAMID_SIMPLE, v1::PYRAMID_ITTI));
  EXPECT_THAT(capabilities.color_encodings(),
              ::testing::ElementsAre("rgb8", "bgr8"));
  EXPECT_THAT(capabilities.depth_encodings(),
              ::testing::ElementsAre("16UC1", "32FC1"));
  EXPECT_EQ(capabilities.max_width(), 1920u);
  // The largest raw 1920x1080 frame and 1 MiB.
  EXPECT_EQ(capabilities.max_message_bytes(), 1920u * 1080u * 7u + (1u << 20));
  EXPECT_THAT(capabilities.segmentation_methods(),
              ::testing::ElementsAre(v1::SEGMENTATION_METHOD_COS,
                                     v1::SEGMENTATION_METHOD_EBS));
  ASSERT_EQ(capabilities.models_size(), 4);
  EXPECT_EQ(capabilities.models(0).name(), "cos_svm");
  EXPECT_THAT(capabilities.models(0).version(), ::testing::StartsWith("cos-"));
  EXPECT_EQ(capabilities.models(1).name(), "ebs_edges");
  EXPECT_THAT(capabilities.models(1).version(),
              ::testing::StartsWith("ebs-v1-"));
  EXPECT_EQ(capabilities.models(2).name(), "inc_relations");
  // The active-stereo family's own INC model (models/active_stereo/).
  EXPECT_EQ(capabilities.models(3).name(), "inc_relations.active_stereo");
  EXPECT_THAT(capabilities.models(3).version(), ::testing::StartsWith("inc-"));
  EXPECT_NE(capabilities.models(3).version(), capabilities.models(2).version());
  // Every sensor model core has, time of flight among them.
  EXPECT_THAT(capabilities.sensor_models(),
              ::testing::ElementsAre(v1::SENSOR_MODEL_GENERIC,
                                     v1::SENSOR_MODEL_KINECT_V1,
                                     v1::SENSOR_MODEL_ACTIVE_STEREO,
                                     v1::SENSOR_MODEL_TIME_OF_FLIGHT));
  EXPECT_TRUE(capabilities.segment_incremental());
  EXPECT_EQ(capabilities.default_detect_options().max_points(), 100u);
}

// Past the descriptor high-water mark (here any use at all) health turns
// NOT_SERVING, so that a liveness probe notices a server that cannot
// accept; the gauges show the count.
TEST_F(ServerTest, HealthIsNotServingWhileDescriptorsRunOut) {
  ServerConfig config = DefaultConfig();
  config.fd_high_water = 1e-6;
  config.fd_check_interval_s = 0.05;
  StartServer(config, /*wait_serving=*/false);
  EXPECT_TRUE(
      WaitFor([this] { return server_->out_of_descriptors(); }, kCallTimeout));
  EXPECT_TRUE(
      WaitFor([this] { return server_->warmed_up(); }, testing::kStartTimeout));
  EXPECT_EQ(HealthStatus(channel_, ""), "NOT_SERVING");
  const std::string metrics = Scrape();
  EXPECT_GT(MetricValue(metrics, "fovea_open_file_descriptors", {}).value_or(0),
            3);
  EXPECT_GT(MetricValue(metrics, "fovea_file_descriptor_limit", {}).value_or(0),
            3);
}

// Clients that open /metrics and never finish their request cannot block
// the scrapes (two of them did, with two handler threads and no request
// timeout).
TEST_F(ServerTest, SlowMetricsClientsDoNotBlockScrapes) {
  StartServer();
  std::vector<int> slow;
  for (int i = 0; i < 8; ++i) {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(server_->metrics_port()));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(
        connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
    const char partial[] = "GET /metrics HTTP/1.1\r\nHost: x\r\n";
    ASSERT_GT(send(fd, partial, sizeof(partial) - 1, 0), 0);
    slow.push_back(fd);
  }
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THAT(Scrape(), HasSubstr("fovea_build_info"));
  EXPECT_LT(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count(),
      2.0);
  for (const int fd : slow) close(fd);
}

TEST_F(ServerTest, HealthServingAfterWarmUpThenNotServingOnDrain) {
  ServerConfig config = DefaultConfig();
  config.warm_up = true;
  StartServer(config);
  EXPECT_TRUE(server_->warmed_up());
  EXPECT_EQ(HealthStatus(channel_, ""), "SERVING");
  EXPECT_EQ(HealthStatus(channel_, "fovea.v1.Perception"), "SERVING");
  server_->Drain();
  EXPECT_EQ(HealthStatus(channel_, ""), "NOT_SERVING");
  EXPECT_EQ(HealthStatus(channel_, "fovea.v1.Perception"), "NOT_SERVING");
  // Draining still serves calls until Shutdown.
  v1::DetectResponse response;
  EXPECT_TRUE(Detect(MakeSyntheticRequest(1, false).request, &response).ok());
}

// With --max_connection_age_s the server sends GOAWAY to old connections,
// so a client's channel leaves READY by itself (and re-resolves its target
// when it reconnects); without it the channel would stay READY for good.
TEST_F(ServerTest, MaxConnectionAgeMakesClientsReconnect) {
  ServerConfig config = DefaultConfig();
  config.max_connection_age_s = 0.5;
  config.max_connection_age_grace_s = 1.0;
  StartServer(config);
  ASSERT_EQ(HealthStatus(channel_, ""), "SERVING");
  ASSERT_EQ(channel_->GetState(false), GRPC_CHANNEL_READY);
  EXPECT_TRUE(channel_->WaitForStateChange(
      GRPC_CHANNEL_READY,
      std::chrono::system_clock::now() + std::chrono::seconds(30)));
  // And the next call simply reconnects.
  EXPECT_EQ(HealthStatus(channel_, ""), "SERVING");
}

TEST(ServerConfigTest, NegativeOrHugeConnectionAgeNamesTheFlag) {
  ServerConfig config;
  config.max_connection_age_s = -1.0;
  EXPECT_THAT(Validate(config).message(),
              ::testing::HasSubstr("--max_connection_age_s"));
  config.max_connection_age_s = 1e9;
  EXPECT_THAT(Validate(config).message(),
              ::testing::HasSubstr("--max_connection_age_s"));
  config.max_connection_age_s = 300.0;
  config.max_connection_age_grace_s = std::nan("");
  EXPECT_THAT(Validate(config).message(),
              ::testing::HasSubstr("--max_connection_age_grace_s"));
  config.max_connection_age_grace_s = 30.0;
  EXPECT_TRUE(Validate(config).ok());
}

}  // namespace
}  // namespace fovea::server
