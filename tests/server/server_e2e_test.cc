// End to end: an in-process FoveaServer on loopback, a real gRPC channel.

#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
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

// The label of the default channel's stage metric, {stage="saliency.sym3d"}.
std::string DefaultSaliencyStageLabel() {
  return absl::StrCat("stage=\"saliency.",
                      AbslView(SaliencyOpName(DetectOptions().channels[0].op)),
                      "\"");
}

using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::kCallTimeout;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricIncrease;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::SyntheticRequest;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

// One worker and no queue: a held call is the only one the server takes.
ServerConfig OneWorkerNoQueue() {
  ServerConfig config;
  config.concurrency = 1;
  config.queue = 0;
  return config;
}

TEST_F(ServerTest, DetectFirstPointLiesOnAnObject) {
  StartServer();
  int on_object = 0;
  constexpr int kSeeds = 6;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const bool depth_16uc1 = seed % 2 == 0;
    SyntheticRequest scene = MakeSyntheticRequest(seed, depth_16uc1);
    v1::DetectResponse response;
    const grpc::Status status = Detect(scene.request, &response);
    ASSERT_TRUE(status.ok())
        << "seed " << seed << ": " << status.error_message();
    EXPECT_EQ(response.request_id(), scene.request.request_id());
    EXPECT_EQ(response.frame_id(), "camera");
    EXPECT_EQ(response.stamp_ns(), 1000 + seed);
    ASSERT_GT(response.points_size(), 0) << "seed " << seed;
    for (int i = 0; i < response.points_size(); ++i) {
      EXPECT_EQ(response.points(i).rank(), static_cast<uint32_t>(i));
    }
    const v1::AttentionPoint& first = response.points(0);
    const int label = scene.labels[first.v() * scene.width + first.u()];
    if (label >= 20) ++on_object;
    RecordProperty("seed_" + std::to_string(seed) + "_first_label", label);
    ASSERT_GE(response.timings_size(), 3);
    EXPECT_EQ(response.timings(0).stage(), "queue");
    EXPECT_EQ(response.timings(1).stage(), "decode");
    EXPECT_EQ(response.timings(response.timings_size() - 1).stage(), "encode");
  }
  // Most first points on objects.
  EXPECT_GE(on_object, kSeeds - 1) << on_object << " of " << kSeeds;
}

TEST_F(ServerTest, MalformedFrameIsInvalidArgumentAndServerGoesOn) {
  StartServer();
  SyntheticRequest good = MakeSyntheticRequest(3, false);
  v1::DetectRequest bad = good.request;
  bad.mutable_frame()->mutable_color()->set_step(100);  // < 640 * 3
  v1::DetectResponse response;
  const grpc::Status status = Detect(bad, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("frame.color.step"));

  EXPECT_TRUE(Detect(good.request, &response).ok());
}

TEST_F(ServerTest, OversizedFrameIsInvalidArgumentAndServerGoesOn) {
  StartServer();
  // Consistent in itself, but wider than the default 1920 limit.
  v1::DetectRequest wide;
  constexpr int kWidth = 2000;
  constexpr int kHeight = 4;
  v1::Image* color = wide.mutable_frame()->mutable_color();
  color->set_width(kWidth);
  color->set_height(kHeight);
  color->set_encoding("rgb8");
  color->set_step(kWidth * 3);
  color->set_data(std::string(kWidth * 3 * kHeight, '\x80'));
  v1::Image* depth = wide.mutable_frame()->mutable_depth();
  depth->set_width(kWidth);
  depth->set_height(kHeight);
  depth->set_encoding("16UC1");
  depth->set_step(kWidth * 2);
  depth->set_data(std::string(kWidth * 2 * kHeight, '\x03'));
  *wide.mutable_frame()->mutable_intrinsics() =
      MakeSyntheticRequest(1, false).request.frame().intrinsics();
  v1::DetectResponse response;
  const grpc::Status status = Detect(wide, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("width"));
  EXPECT_THAT(status.error_message(), HasSubstr("frame."));

  EXPECT_TRUE(Detect(MakeSyntheticRequest(1, false).request, &response).ok());
}

TEST_F(ServerTest, RawFrameOf1280x720FitsTheDefaultMessageLimit) {
  StartServer();
  // About 6.5 MB raw (rgb8 + 32FC1): above gRPC's default 4 MiB.
  synth::SceneSpec spec = synth::RandomSceneSpec(4, {});
  spec.width = 1280;
  spec.height = 720;
  spec.intrinsics = {1050.0, 1050.0, 639.5, 359.5};
  const synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, 4);
  v1::DetectRequest request;
  *request.mutable_frame() =
      ToProtoFrame(scene.frame.frame, DepthEncoding::k32FC1);
  ASSERT_GT(request.ByteSizeLong(), 4u << 20);
  v1::DetectResponse response;
  const grpc::Status status = Detect(request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST_F(ServerTest,
       AWholeRoomAt1280x720GivesTheTableAndItsObjectsAtInputPixels) {
  StartServer();
  synth::RoomOptions room;
  room.sensor = synth::RoomSensor::kActiveStereo;
  room.width = 1280;
  room.height = 720;
  const synth::SynthScene scene = synth::GenerateRoom(7, room);
  v1::SegmentIncrementalRequest request;
  *request.mutable_frame() =
      ToProtoFrame(scene.frame.frame, DepthEncoding::k16UC1);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(60));
  auto reader = stub_->SegmentIncremental(&context, request);
  std::vector<v1::SegmentResponse> messages;
  v1::SegmentResponse response;
  while (reader->Read(&response)) messages.push_back(response);
  const grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(messages.size(), 3u);
  // The first message says which support was chosen and why.
  const v1::SupportPlane& plane = messages.front().support_plane();
  EXPECT_GT(plane.normal().x() * scene.table_normal_camera.x() +
                plane.normal().y() * scene.table_normal_camera.y() +
                plane.normal().z() * scene.table_normal_camera.z(),
            std::cos(3.0 * M_PI / 180.0));
  EXPECT_NEAR(plane.d(), scene.table_d_camera, 0.02);
  EXPECT_GE(plane.candidate_count(), 1u);
  EXPECT_GT(plane.score().objects(), 0u);
  // Masks come back at the input size, on the table's objects.
  for (size_t i = 1; i + 1 < messages.size(); ++i) {
    const v1::ObjectResult& object = messages[i].object();
    EXPECT_EQ(object.mask().width(), 1280u);
    EXPECT_EQ(object.mask().height(), 720u);
    EXPECT_LT(object.box().u() + object.box().width(), 1281u);
    const int label =
        scene.frame.labels.at<int>(static_cast<int>(object.seed().v()),
                                   static_cast<int>(object.seed().u()));
    EXPECT_TRUE(label >= 20 || label == 0)
        << "object " << i - 1 << "'s seed lies on label " << label;
  }
}

TEST_F(ServerTest, BadSceneHintsAreInvalidArgumentNamingTheField) {
  StartServer();
  v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  request.mutable_options()->mutable_scene()->mutable_gravity()->set_y(2.0);
  v1::DetectResponse response;
  grpc::Status status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("options.scene.gravity"));
  request = MakeSyntheticRequest(1, false).request;
  request.mutable_options()
      ->mutable_scene()
      ->mutable_workspace()
      ->mutable_box();
  status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("options.scene.workspace.box"));
  // A good gravity is used: the table is found with it.
  request = MakeSyntheticRequest(1, false).request;
  const synth::SynthScene scene = synth::GenerateScene(1);
  v1::Vector3* g =
      request.mutable_options()->mutable_scene()->mutable_gravity();
  g->set_x(-scene.table_normal_camera.x());
  g->set_y(-scene.table_normal_camera.y());
  g->set_z(-scene.table_normal_camera.z());
  status = Detect(request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_LT(response.support_plane().score().tilt_deg(), 3.0);
}

TEST_F(ServerTest, CueWithoutItsValueAndTooManyPointsAreInvalid) {
  StartServer();
  v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  request.mutable_options()->add_saliency()->set_op(
      v1::SALIENCY_OPERATOR_TARGET_COLOR);
  v1::DetectResponse response;
  grpc::Status status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("options.target_color_rgb"));

  request.mutable_options()->clear_saliency();
  request.mutable_options()->set_max_points(101);
  status = Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("options.max_points"));
}

TEST_F(ServerTest, ShortDeadlineIsDeadlineExceeded) {
  StartServer();
  v1::DetectResponse response;
  const grpc::Status status = Detect(MakeSyntheticRequest(2, false).request,
                                     &response, std::chrono::milliseconds(1));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
}

TEST_F(ServerTest, JobWhoseDeadlinePassedInTheQueueIsNotComputed) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 1;
  StartServer(config);
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  const std::string before = Scrape();
  const double decodes_before =
      MetricValue(before, "fovea_stage_duration_seconds_count",
                  {"stage=\"decode\""})
          .value_or(-1);

  std::future<grpc::Status> held = StartHeldDetect(request);
  ASSERT_EQ(gate_.entered(), 1);
  std::future<grpc::Status> expiring =
      DetectAsync(request, std::chrono::milliseconds(1000));
  ASSERT_TRUE(
      WaitFor([this] { return server_->queued_jobs() == 1; }, kCallTimeout));
  // The client gives up while its job waits behind the held one.
  EXPECT_EQ(expiring.get().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  gate_.Open();
  EXPECT_TRUE(held.get().ok());

  // The server answered the expired job DEADLINE_EXCEEDED without decoding
  // its frame: one decode (the held call's) more than before.
  // The metrics are the process's, so count from `before` (an earlier
  // test's 1 ms deadline may or may not have reached the server).
  ASSERT_TRUE(WaitFor(
      [&] {
        return Handled(Scrape(), "Detect", "DeadlineExceeded") ==
               Handled(before, "Detect", "DeadlineExceeded") + 1;
      },
      kCallTimeout));
  const double decodes_after =
      MetricValue(Scrape(), "fovea_stage_duration_seconds_count",
                  {"stage=\"decode\""})
          .value_or(-1);
  EXPECT_EQ(decodes_after, decodes_before + 1);
}

// ShortDeadlineIsDeadlineExceeded passes even against a server that
// ignores deadlines (the client gives up on its own). Here the job is held
// at core's first stage boundary (after the cloud and normals) until the
// deadline has passed: the server must stop it there, before saliency,
// and answer DEADLINE_EXCEEDED itself.
// How much later than the client's the server's copy of a deadline may
// be (the request's transit time, generously on a loaded machine).
constexpr auto kServerDeadlineMargin = std::chrono::milliseconds(500);

TEST_F(ServerTest, DeadlinePassingMidPipelineStopsTheJobBeforeSaliency) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  StartServer(config);
  const std::string before = Scrape();
  // Boundary 1 is the server's, after decoding; 2 is core's first.
  constexpr int kCoreFirstBoundary = 2;
  stage_gate_.CloseAtPass(kCoreFirstBoundary);
  std::future<grpc::Status> call = DetectAsync(
      MakeSyntheticRequest(1, false).request, std::chrono::seconds(3));
  ASSERT_TRUE(
      WaitFor([this] { return stage_gate_.entered() == kCoreFirstBoundary; },
              kCallTimeout));
  EXPECT_EQ(call.get().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The server's copy of the deadline is re-based on the request's arrival,
  // so it can lie a little after the client's; until it passes, the check
  // sees only the client's cancellation (CANCELLED). Hold a while longer so
  // that the server's deadline check decides.
  std::this_thread::sleep_for(kServerDeadlineMargin);
  stage_gate_.Open();

  // The server itself answers DEADLINE_EXCEEDED once released (the client
  // has given up already: wait for the call to be counted and finished)...
  ASSERT_TRUE(WaitFor(
      [&] {
        const std::string text = Scrape();
        return Handled(text, "Detect", "DeadlineExceeded") ==
                   Handled(before, "Detect", "DeadlineExceeded") + 1 &&
               MetricValue(text, "fovea_inflight_requests", {}) == 0;
      },
      kCallTimeout));
  const std::string after = Scrape();
  EXPECT_EQ(Handled(after, "Detect", "OK"), Handled(before, "Detect", "OK"));
  // ...at the boundary where it was held: a job that went on would pass
  // the boundary after its saliency channel too.
  EXPECT_EQ(stage_gate_.entered(), kCoreFirstBoundary);
  EXPECT_EQ(MetricValue(after, "fovea_stage_duration_seconds_count",
                        {DefaultSaliencyStageLabel()}),
            MetricValue(before, "fovea_stage_duration_seconds_count",
                        {DefaultSaliencyStageLabel()}));
}

TEST_F(ServerTest, FullQueueIsResourceExhausted) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 1;
  StartServer(config);
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  const std::string before = Scrape();  // the binary's tests share metrics

  std::future<grpc::Status> running = StartHeldDetect(request);
  ASSERT_EQ(gate_.entered(), 1);
  std::future<grpc::Status> queued = DetectAsync(request);
  ASSERT_TRUE(
      WaitFor([this] { return server_->queued_jobs() == 1; }, kCallTimeout));

  // One worker busy, one job queued: the next is refused at once.
  v1::DetectResponse response;
  const grpc::Status refused = Detect(request, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("busy"));

  gate_.Open();
  EXPECT_TRUE(running.get().ok());
  EXPECT_TRUE(queued.get().ok());
  EXPECT_EQ(MetricIncrease(
                before, Scrape(), "grpc_server_handled_total",
                {"grpc_method=\"Detect\"", "grpc_code=\"ResourceExhausted\""}),
            1);
}

// A sequential client whose calls time out while they wait for the busy
// worker: each call ends at its deadline and frees its queue slot, so the
// next one is queued again instead of refused.
TEST_F(ServerTest, CallsWhoseDeadlinePassedInTheQueueFreeTheirSlotAtOnce) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 1;
  StartServer(config);
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  // The deadline must be long enough for a call to reach the queue, or gRPC
  // drops it before the server sees it and there is nothing to free: under
  // the sanitizers on a slow machine a call took more than 100 ms to arrive
  // (CI, 2026-12-05). So it is four times the longest of three calls of the
  // same size that the server refuses as soon as it has read them.
  v1::DetectRequest refused = request;
  refused.mutable_frame()->mutable_intrinsics()->set_fx(-1);
  auto arrival = std::chrono::steady_clock::duration::zero();
  for (int i = 0; i < 3; ++i) {
    v1::DetectResponse response;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(Detect(refused, &response).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
    arrival = std::max(arrival, std::chrono::steady_clock::now() - start);
  }
  const auto kDeadline = std::clamp(
      std::chrono::duration_cast<std::chrono::milliseconds>(4 * arrival),
      std::chrono::milliseconds(100), std::chrono::milliseconds(2000));
  // The metrics are the process's: other tests of this binary may have
  // counted calls before this one.
  const std::string before = Scrape();
  const double deadline_exceeded =
      Handled(before, "Detect", "DeadlineExceeded");
  const double exhausted = Handled(before, "Detect", "ResourceExhausted");
  std::future<grpc::Status> running = StartHeldDetect(request);
  for (int i = 0; i < 8; ++i) {
    v1::DetectResponse response;
    const auto start = std::chrono::steady_clock::now();
    const grpc::Status status = Detect(request, &response, kDeadline);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED)
        << "call " << i << ": " << status.error_message();
    EXPECT_LT(seconds, 5.0) << "call " << i;
    // The server ends the call itself; wait until it has. (Waiting for an
    // empty queue is not enough: a call the client gave up on may not be
    // queued yet, and would take the next call's slot.)
    ASSERT_TRUE(WaitFor(
        [&] {
          return Handled(Scrape(), "Detect", "DeadlineExceeded") ==
                 deadline_exceeded + i + 1;
        },
        kCallTimeout));
  }
  gate_.Open();
  EXPECT_TRUE(running.get().ok());
  const std::string metrics = Scrape();
  EXPECT_EQ(Handled(metrics, "Detect", "ResourceExhausted"), exhausted);
  EXPECT_EQ(MetricIncrease(before, metrics, "fovea_calls_shed_total",
                           {"reason=\"abandoned_in_queue\""}),
            8);
}

TEST_F(ServerTest, Sym3dOnAnIttiPyramidWithTJunctionsFindsObjects) {
  StartServer();
  SyntheticRequest synthetic = MakeSyntheticRequest(2, false);
  v1::DetectOptions* options = synthetic.request.mutable_options();
  options->add_saliency()->set_op(v1::SALIENCY_OPERATOR_SYM3D);
  options->set_pyramid(v1::PYRAMID_ITTI);
  options->set_normalization(v1::NORMALIZATION_NLM);
  options->set_extraction(v1::EXTRACTION_TJ);
  v1::DetectResponse response;
  const grpc::Status status = Detect(synthetic.request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(response.points_size(), 0);
}

TEST_F(ServerTest, MetricsScrapeShowsCountersWithGrpcLabels) {
  StartServer();
  const std::string before = Scrape();
  const std::vector<std::string> detect = {
      "grpc_method=\"Detect\"", "grpc_service=\"fovea.v1.Perception\"",
      "grpc_type=\"unary\""};
  auto with = [&detect](const std::string& label) {
    std::vector<std::string> labels = detect;
    labels.push_back(label);
    return labels;
  };
  // Zero-initialised series exist before any call (codes no test in this
  // binary produces, since the tests may share one process).
  EXPECT_EQ(MetricValue(before, "grpc_server_handled_total",
                        with("grpc_code=\"DataLoss\"")),
            0);
  EXPECT_EQ(MetricValue(before, "grpc_server_handled_total",
                        with("grpc_code=\"Unauthenticated\"")),
            0);
  EXPECT_EQ(MetricValue(before, "grpc_server_handled_total",
                        {"grpc_method=\"SegmentIncremental\"",
                         "grpc_type=\"server_stream\"",
                         "grpc_code=\"DeadlineExceeded\""}),
            0);
  EXPECT_EQ(MetricValue(before, "fovea_build_info",
                        {"version=\"" + std::string(ServerVersion()) + "\""}),
            1);
  EXPECT_TRUE(MetricValue(before, "fovea_stage_duration_seconds_count",
                          {"stage=\"support_plane\""})
                  .has_value());
  EXPECT_TRUE(MetricValue(before, "grpc_server_handling_seconds_bucket",
                          {"grpc_method=\"Detect\"", "le=\"0.005\""})
                  .has_value());
  const double started =
      MetricValue(before, "grpc_server_started_total", detect).value_or(-1);
  const double invalid = Handled(before, "Detect", "InvalidArgument");
  const double ok = Handled(before, "Detect", "OK");

  v1::DetectRequest bad = MakeSyntheticRequest(1, false).request;
  bad.mutable_frame()->mutable_depth()->set_step(7);
  v1::DetectResponse response;
  EXPECT_EQ(Detect(bad, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  ASSERT_TRUE(Detect(MakeSyntheticRequest(1, false).request, &response).ok());

  // Handled is recorded before the status goes out, so it is there now.
  const std::string after = Scrape();
  EXPECT_EQ(MetricValue(after, "grpc_server_started_total", detect),
            started + 2);
  EXPECT_EQ(Handled(after, "Detect", "InvalidArgument"), invalid + 1);
  EXPECT_EQ(Handled(after, "Detect", "OK"), ok + 1);
  EXPECT_EQ(MetricValue(after, "grpc_server_msg_received_total", detect),
            MetricValue(before, "grpc_server_msg_received_total", detect)
                    .value_or(-1) +
                2);
  EXPECT_EQ(
      MetricValue(after, "grpc_server_msg_sent_total", detect),
      MetricValue(before, "grpc_server_msg_sent_total", detect).value_or(-1) +
          1);
  EXPECT_EQ(MetricValue(after, "grpc_server_handling_seconds_count", detect),
            MetricValue(before, "grpc_server_handling_seconds_count", detect)
                    .value_or(-1) +
                2);
  const std::string default_stage = DefaultSaliencyStageLabel();
  EXPECT_GE(
      MetricValue(after, "fovea_stage_duration_seconds_count", {default_stage})
          .value_or(-1),
      1);
  EXPECT_EQ(
      MetricValue(after, "fovea_queue_wait_seconds_count", {}),
      MetricValue(before, "fovea_queue_wait_seconds_count", {}).value_or(-1) +
          2);
  EXPECT_EQ(MetricValue(after, "fovea_inflight_requests", {}), 0);
}

TEST_F(ServerTest, ShutdownLetsInFlightCallFinish) {
  StartServer(OneWorkerNoQueue());
  std::future<grpc::Status> in_flight =
      StartHeldDetect(MakeSyntheticRequest(1, false).request);
  ASSERT_EQ(gate_.entered(), 1);

  std::thread shutdown([this] { server_->Shutdown(absl::Seconds(30)); });
  // Once the server stops accepting, new calls fail; then let the held
  // call go on: it must still complete.
  ASSERT_TRUE(WaitFor(
      [this] {
        grpc::ClientContext context;
        context.set_deadline(std::chrono::system_clock::now() +
                             std::chrono::seconds(2));
        v1::GetCapabilitiesResponse capabilities;
        return !stub_
                    ->GetCapabilities(&context, v1::GetCapabilitiesRequest(),
                                      &capabilities)
                    .ok();
      },
      kCallTimeout));
  gate_.Open();
  EXPECT_TRUE(in_flight.get().ok());
  shutdown.join();
}

// On Shutdown: health NOT_SERVING at once while calls are still served
// for the drain delay, then new calls are refused; an open health Watch
// (as round-robin clients keep) does not hold the shutdown for the grace
// period: it ends as soon as the calls in flight have.
TEST_F(ServerTest, ShutdownDrainsThenRefusesAndEndsWatchStreams) {
  ServerConfig config = DefaultConfig();
  config.drain_delay_s = 3.0;
  StartServer(config);
  auto health = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext watch_context;
  watch_context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  grpc::health::v1::HealthCheckRequest watch_request;
  auto watch = health->Watch(&watch_context, watch_request);
  grpc::health::v1::HealthCheckResponse update;
  ASSERT_TRUE(watch->Read(&update));
  EXPECT_EQ(update.status(), grpc::health::v1::HealthCheckResponse::SERVING);

  // Made first: under a sanitizer, making it took longer than the delay.
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  const auto start = std::chrono::steady_clock::now();
  std::thread shutdown([this] { server_->Shutdown(absl::Seconds(30)); });
  ASSERT_TRUE(watch->Read(&update));
  EXPECT_EQ(update.status(),
            grpc::health::v1::HealthCheckResponse::NOT_SERVING);
  // Still served during the drain delay (UNAVAILABLE after it).
  v1::DetectResponse response;
  EXPECT_TRUE(Detect(request, &response).ok());
  while (watch->Read(&update)) {
  }
  watch->Finish();
  shutdown.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  EXPECT_GE(seconds, 3.0);
  EXPECT_LT(seconds, 20.0);  // not the 30 s grace
}

TEST_F(ServerTest, ShutdownCancelsCallsPastTheGracePeriod) {
  StartServer(OneWorkerNoQueue());
  std::future<grpc::Status> in_flight =
      StartHeldDetect(MakeSyntheticRequest(1, false).request);
  ASSERT_EQ(gate_.entered(), 1);

  const auto start = std::chrono::steady_clock::now();
  std::thread shutdown([this] { server_->Shutdown(absl::Milliseconds(200)); });
  // The held call is cancelled once the grace period is over, long before
  // its own 30 s deadline.
  ASSERT_EQ(in_flight.wait_for(kCallTimeout), std::future_status::ready);
  const grpc::Status status = in_flight.get();
  EXPECT_FALSE(status.ok());
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  gate_.Open();  // its job now sees CANCELLED and finishes
  shutdown.join();
}

}  // namespace
}  // namespace fovea::server
