// End to end, streams: Segment and SegmentIncremental over a real gRPC
// channel to an in-process FoveaServer (ServerTest,
// tests/server/server_fixture.h).

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
using ::fovea::server::testing::MetricIncrease;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::SyntheticRequest;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

// Every message of a Segment call, and its status.
struct SegmentCall {
  std::vector<v1::SegmentResponse> messages;
  grpc::Status status;
};

SegmentCall CallSegment(v1::Perception::Stub& stub,
                        const v1::SegmentRequest& request,
                        int read_at_most = 1000) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(60));
  auto reader = stub.Segment(&context, request);
  SegmentCall call;
  v1::SegmentResponse response;
  while (static_cast<int>(call.messages.size()) < read_at_most &&
         reader->Read(&response)) {
    call.messages.push_back(response);
  }
  if (static_cast<int>(call.messages.size()) >= read_at_most) {
    context.TryCancel();
    while (reader->Read(&response)) {
    }
  }
  call.status = reader->Finish();
  return call;
}

// A client that never reads its stream (a transport window of about one
// byte, no window growth) holds the worker only for the stall timeout: the
// stream is cancelled, counted, and the worker serves the next call.
TEST_F(ServerTest, StreamWhoseClientNeverReadsIsCancelledAndFreesItsWorker) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 1;
  config.stream_stall_timeout_s = 0.3;
  StartServer(config);
  std::unique_ptr<v1::Perception::Stub> lazy =
      ::fovea::server::testing::SlowReaderStub(server_->port());
  v1::SegmentRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  // Each object's mask goes as a full-frame run-length list: make the
  // messages large enough to fill any window.
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(60));
  // The binary's tests share one process, and its metrics.
  const std::string before = Scrape();
  auto never_read = lazy->Segment(&context, request);
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricIncrease(before, Scrape(), "fovea_calls_shed_total",
                              {"reason=\"stalled_stream\""}) >= 1;
      },
      kCallTimeout));
  // The worker is free: a Detect from another client succeeds.
  v1::DetectResponse response;
  EXPECT_TRUE(Detect(MakeSyntheticRequest(1, false).request, &response,
                     std::chrono::milliseconds(20000))
                  .ok());
  context.TryCancel();
  v1::SegmentResponse ignored;
  while (never_read->Read(&ignored)) {
  }
  EXPECT_EQ(never_read->Finish().error_code(), grpc::StatusCode::CANCELLED);
}

// grpc-timeout allows 99999999 hours (11,000 years): past 2262, beyond
// std::chrono's nanosecond clock. Such a call is served, not refused as
// already late.
TEST_F(ServerTest, DeadlineFarInTheFutureIsNoDeadline) {
  StartServer();
  grpc::ClientContext context;
  context.set_deadline(
      gpr_time_add(gpr_now(GPR_CLOCK_REALTIME),
                   gpr_time_from_hours(99999999, GPR_TIMESPAN)));
  v1::DetectResponse response;
  const grpc::Status status = stub_->Detect(
      &context, MakeSyntheticRequest(1, false).request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(response.points_size(), 0);
}

TEST_F(ServerTest, SegmentStreamsPointsThenObjectsThenTheSummary) {
  StartServer();
  v1::SegmentRequest request;
  request.set_request_id("seg-1");
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  const std::string before = Scrape();
  const SegmentCall call = CallSegment(*stub_, request);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_GE(call.messages.size(), 3u);
  EXPECT_GT(call.messages.front().attention_points_size(), 0);
  EXPECT_FALSE(call.messages.front().has_object());
  const v1::SegmentResponse& last = call.messages.back();
  EXPECT_TRUE(last.last());
  EXPECT_EQ(last.summary().stop_reason(), v1::STOP_REASON_DONE);
  const int objects = static_cast<int>(call.messages.size()) - 2;
  EXPECT_EQ(last.summary().object_count(), static_cast<uint32_t>(objects));
  double previous = 0.0;
  for (int i = 1; i <= objects; ++i) {
    const v1::ObjectResult& object = call.messages[i].object();
    EXPECT_EQ(call.messages[i].request_id(), "seg-1");
    EXPECT_EQ(object.index(), static_cast<uint32_t>(i - 1));
    EXPECT_GT(object.area(), 0u);
    EXPECT_EQ(object.mask().width(), 640u);
    uint64_t pixels = 0;
    for (const uint32_t run : object.mask().counts()) pixels += run;
    EXPECT_EQ(pixels, 640u * 480u);
    EXPECT_GE(object.seconds_since_request(), previous);
    previous = object.seconds_since_request();
  }
  const std::string text = Scrape();
  auto added = [&](const std::string& name) {
    return MetricIncrease(before, text, name, {"grpc_method=\"Segment\""});
  };
  EXPECT_EQ(added("fovea_objects_per_request_count"), 1);
  EXPECT_EQ(added("fovea_time_to_first_object_seconds_count"),
            objects > 0 ? 1 : 0);
  EXPECT_EQ(added("grpc_server_msg_sent_total"),
            static_cast<double>(call.messages.size()));
}

// Every object comes with its box standing on the support (the box's z
// axis is the support frame's, its base on the plane for an object on the
// table, above it for one resting on another), and with the points asked
// for: indices into the frame that lie
// in the object's mask, or float32 triples on the object's box.
TEST_F(ServerTest, ObjectsCarryTheirBoxOnTheSupportAndThePointsAskedFor) {
  StartServer();
  v1::SegmentIncrementalRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  request.mutable_object_points()->set_format(
      v1::ObjectPointsOptions::FORMAT_XYZ);
  request.mutable_object_points()->set_max_points(200);
  grpc::ClientContext context;
  auto reader = stub_->SegmentIncremental(&context, request);
  std::vector<v1::SegmentResponse> messages;
  v1::SegmentResponse response;
  while (reader->Read(&response)) messages.push_back(response);
  ASSERT_TRUE(reader->Finish().ok());
  ASSERT_GE(messages.size(), 3u);
  for (size_t i = 1; i + 1 < messages.size(); ++i) {
    const v1::ObjectResult& object = messages[i].object();
    ASSERT_TRUE(object.has_oriented_box()) << i;
    const v1::OrientedBox& box = object.oriented_box();
    EXPECT_GT(box.size().x(), 0.01);
    EXPECT_GE(box.size().x(), box.size().y());
    const Eigen::Quaterniond q(box.orientation().w(), box.orientation().x(),
                               box.orientation().y(), box.orientation().z());
    EXPECT_NEAR(q.norm(), 1.0, 1e-6);
    const Eigen::Quaterniond s(object.support_frame().orientation().w(),
                               object.support_frame().orientation().x(),
                               object.support_frame().orientation().y(),
                               object.support_frame().orientation().z());
    // Both z axes are the support normal.
    EXPECT_GT((q * Eigen::Vector3d::UnitZ()).dot(s * Eigen::Vector3d::UnitZ()),
              0.9999);
    // The top above the plane: the box's height for an object on the
    // table, more for one resting on another.
    EXPECT_GE(object.height_above_support(), box.size().z() - 1e-6);
    EXPECT_NEAR(object.footprint_area(), box.size().x() * box.size().y(), 1e-9);
    // The xyz points: at most 200, each inside the box (with the trimmed
    // 1 % of heights a few mm out).
    const v1::ObjectPoints& points = object.points();
    ASSERT_GT(points.count(), 0u);
    EXPECT_LE(points.count(), 200u);
    ASSERT_EQ(points.xyz().size(), points.count() * 12u);
    EXPECT_EQ(points.indices_size(), 0);
    const Eigen::Vector3d centre(box.center().x(), box.center().y(),
                                 box.center().z());
    int inside = 0;
    for (uint32_t k = 0; k < points.count(); ++k) {
      float xyz[3];
      std::memcpy(xyz, points.xyz().data() + 12 * k, sizeof xyz);
      const Eigen::Vector3d local =
          q.conjugate() * (Eigen::Vector3d(xyz[0], xyz[1], xyz[2]) - centre);
      inside += std::abs(local.x()) <= box.size().x() / 2 + 0.005 &&
                std::abs(local.y()) <= box.size().y() / 2 + 0.005 &&
                std::abs(local.z()) <= box.size().z() / 2 + 0.005;
    }
    EXPECT_GT(inside, static_cast<int>(points.count() * 0.95)) << i;
  }
  // Indices, as many as the mask has pixels, each on the mask.
  v1::SegmentRequest segment;
  *segment.mutable_frame() = request.frame();
  segment.mutable_object_points()->set_format(
      v1::ObjectPointsOptions::FORMAT_INDICES);
  const SegmentCall call = CallSegment(*stub_, segment);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_GE(call.messages.size(), 3u);
  const v1::ObjectResult& first = call.messages[1].object();
  EXPECT_EQ(first.points().count(), first.area());
  EXPECT_EQ(first.points().indices_size(), static_cast<int>(first.area()));
  const uint32_t index = first.points().indices(first.area() / 2);
  const cv::Rect box(first.box().u(), first.box().v(), first.box().width(),
                     first.box().height());
  EXPECT_TRUE(box.contains(cv::Point(index % 640, index / 640)));
  // Too many points asked for is refused naming the field.
  segment.mutable_object_points()->set_max_points(1u << 30);
  const SegmentCall refused = CallSegment(*stub_, segment);
  EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.status.error_message(),
              HasSubstr("object_points.max_points"));
}

TEST_F(ServerTest, SegmentKeepsGivenSeedsAndStopsAtMaxObjects) {
  StartServer();
  v1::SegmentRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  // Seeds from a Detect on the same frame: on objects, in this order.
  v1::DetectRequest detect = MakeSyntheticRequest(3, false).request;
  v1::DetectResponse points;
  ASSERT_TRUE(Detect(detect, &points).ok());
  ASSERT_GE(points.points_size(), 2);
  for (int i = 1; i >= 0; --i) {
    v1::AttentionPixel* seed = request.add_seeds();
    seed->set_u(points.points(i).u());
    seed->set_v(points.points(i).v());
  }
  request.set_max_objects(1);
  const SegmentCall call = CallSegment(*stub_, request);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_EQ(call.messages.front().attention_points_size(), 2);
  EXPECT_EQ(call.messages.front().attention_points(0).u(),
            points.points(1).u());
  EXPECT_EQ(call.messages.back().summary().object_count(), 1u);
  EXPECT_EQ(call.messages.back().summary().stop_reason(),
            v1::STOP_REASON_MAX_OBJECTS);
}

TEST_F(ServerTest,
       SegmentRejectsBadRequestsByFieldAndIncrementalIsUnimplemented) {
  StartServer();
  v1::SegmentRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  request.add_seeds()->set_u(5000);
  SegmentCall call = CallSegment(*stub_, request);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("seeds"));
  EXPECT_TRUE(call.messages.empty());
  request.clear_seeds();
  request.mutable_detect_options()->set_max_points(1000);
  call = CallSegment(*stub_, request);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("detect_options."));
  request.clear_detect_options();
  request.mutable_frame()->clear_intrinsics();
  call = CallSegment(*stub_, request);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("intrinsics"));
}

TEST_F(ServerTest, SegmentIncrementalStreamsObjectsInOrderAndStops) {
  StartServer();
  v1::SegmentIncrementalRequest request;
  request.set_request_id("inc-1");
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(60));
  auto reader = stub_->SegmentIncremental(&context, request);
  std::vector<v1::SegmentResponse> messages;
  v1::SegmentResponse response;
  while (reader->Read(&response)) messages.push_back(response);
  const grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(messages.size(), 3u);  // points, an object at least, summary
  EXPECT_GT(messages.front().attention_points_size(), 0);
  const v1::SegmentSummary& summary = messages.back().summary();
  EXPECT_TRUE(messages.back().last());
  EXPECT_EQ(summary.stop_reason(), v1::STOP_REASON_DONE);
  EXPECT_GT(summary.scene_coverage(), 0.9);  // run to the end
  for (size_t i = 1; i + 1 < messages.size(); ++i) {
    EXPECT_EQ(messages[i].object().index(), i - 1);
  }
  // The same with a budget of one object, and with a time budget of
  // nothing: each stops and says why.
  request.set_max_objects(1);
  grpc::ClientContext one;
  auto one_reader = stub_->SegmentIncremental(&one, request);
  messages.clear();
  while (one_reader->Read(&response)) messages.push_back(response);
  ASSERT_TRUE(one_reader->Finish().ok());
  EXPECT_EQ(messages.back().summary().stop_reason(),
            v1::STOP_REASON_MAX_OBJECTS);
  EXPECT_EQ(messages.back().summary().object_count(), 1u);
  request.set_max_objects(0);
  request.set_time_budget_seconds(1e-9);
  const std::string before = Scrape();
  grpc::ClientContext budget;
  auto budget_reader = stub_->SegmentIncremental(&budget, request);
  messages.clear();
  while (budget_reader->Read(&response)) messages.push_back(response);
  ASSERT_TRUE(budget_reader->Finish().ok());
  EXPECT_EQ(messages.back().summary().stop_reason(),
            v1::STOP_REASON_TIME_BUDGET);
  EXPECT_EQ(MetricIncrease(before, Scrape(), "fovea_segment_stops_total",
                           {"grpc_method=\"SegmentIncremental\"",
                            "reason=\"time_budget\""}),
            1);
  // A negative budget is refused naming the field.
  request.set_time_budget_seconds(-1.0);
  grpc::ClientContext bad;
  auto bad_reader = stub_->SegmentIncremental(&bad, request);
  EXPECT_FALSE(bad_reader->Read(&response));
  const grpc::Status refused = bad_reader->Finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("time_budget_seconds"));
}

TEST_F(ServerTest, SegmentDeadlineMidStreamKeepsWhatWasSentAndEndsDeadline) {
  StartServer();
  v1::SegmentRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  request.add_seeds()->set_u(320);
  request.mutable_seeds(0)->set_v(240);
  // Stage boundaries with given seeds: 1 after decoding, 2 after normals,
  // 3 after the support plane; the seeds message is sent; 4 is the check
  // after it. Hold there until the deadline has passed.
  constexpr int kAfterSeedsMessage = 4;
  // Reaching that stage takes seconds under a sanitizer on a loaded
  // machine: one whole call first, undisturbed, and the deadline leaves
  // twice its time (2 s at least) for the held call to get there.
  const auto first_start = std::chrono::steady_clock::now();
  {
    grpc::ClientContext context;
    auto reader = stub_->Segment(&context, request);
    v1::SegmentResponse response;
    while (reader->Read(&response)) {
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  const auto whole_call = std::chrono::steady_clock::now() - first_start;
  const std::string before = Scrape();  // the binary's tests share metrics
  const int passes_before = stage_gate_.entered();
  const int held_pass = passes_before + kAfterSeedsMessage;
  stage_gate_.CloseAtPass(held_pass);
  const auto deadline =
      std::chrono::system_clock::now() +
      std::max<std::chrono::system_clock::duration>(
          std::chrono::seconds(2),
          std::chrono::duration_cast<std::chrono::system_clock::duration>(
              2 * whole_call));
  std::future<SegmentCall> call = std::async(std::launch::async, [&] {
    grpc::ClientContext context;
    context.set_deadline(deadline);
    auto reader = stub_->Segment(&context, request);
    SegmentCall result;
    v1::SegmentResponse response;
    while (reader->Read(&response)) result.messages.push_back(response);
    result.status = reader->Finish();
    return result;
  });
  ASSERT_TRUE(WaitFor([&] { return stage_gate_.entered() == held_pass; },
                      kCallTimeout));
  const SegmentCall ended = call.get();  // returns once the deadline passed
  // The server's copy of the deadline is re-based on the request's arrival,
  // a loopback transit later than the client's: release the worker only
  // once that has surely passed too.
  ASSERT_TRUE(WaitFor(
      [&] {
        return std::chrono::system_clock::now() >
               deadline + std::chrono::milliseconds(200);
      },
      kCallTimeout));
  stage_gate_.Open();
  EXPECT_EQ(ended.status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  ASSERT_EQ(ended.messages.size(), 1u);
  EXPECT_EQ(ended.messages[0].attention_points_size(), 1);
  // The worker stops at its next check and the server goes on.
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricIncrease(before, Scrape(), "grpc_server_handled_total",
                              {"grpc_method=\"Segment\"",
                               "grpc_code=\"DeadlineExceeded\""}) == 1;
      },
      std::chrono::seconds(10)));
  EXPECT_EQ(stage_gate_.entered(), held_pass);  // stopped there
}

TEST_F(ServerTest, SegmentCancelledAfterTheFirstMessageEndsCancelled) {
  StartServer();
  v1::SegmentRequest request;
  *request.mutable_frame() = MakeSyntheticRequest(3, false).request.frame();
  // The binary's tests share one process, and its metrics.
  const std::string before = Scrape();
  const SegmentCall call = CallSegment(*stub_, request, /*read_at_most=*/1);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::CANCELLED);
  // The server finishes the call and goes on serving.
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricIncrease(
                   before, Scrape(), "grpc_server_handled_total",
                   {"grpc_method=\"Segment\"", "grpc_code=\"Canceled\""}) == 1;
      },
      std::chrono::seconds(10)));
  const SegmentCall again = CallSegment(*stub_, request);
  EXPECT_TRUE(again.status.ok()) << again.status.error_message();
}

}  // namespace
}  // namespace fovea::server
