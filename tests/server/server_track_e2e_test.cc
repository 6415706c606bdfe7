// End to end, Track: frame streams over a real gRPC channel to an
// in-process FoveaServer (ServerTest, tests/server/server_fixture.h):
// identities across frames, the freshest frame winning, bad messages named,
// the open-stream limits and the idle timeout.

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/synth/sequence.h"
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
using ::fovea::server::testing::MetricIncrease;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerTest;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

using Stream = grpc::ClientReaderWriter<v1::TrackRequest, v1::TrackResponse>;

v1::TrackRequest Options(const std::string& request_id) {
  v1::TrackRequest request;
  request.mutable_options()->set_request_id(request_id);
  return request;
}

v1::TrackRequest FrameMessage(const synth::SequenceFrame& frame,
                              uint64_t sequence, bool with_pose = true) {
  v1::TrackRequest request;
  v1::TrackFrame* wire = request.mutable_frame();
  *wire->mutable_frame() =
      ToProtoFrame(frame.frame.frame, DepthEncoding::k16UC1);
  wire->set_sequence(sequence);
  if (with_pose) {
    const Eigen::Isometry3f& pose = frame.camera_to_world;
    const Eigen::Quaternionf q(pose.rotation());
    v1::Pose* p = wire->mutable_camera_to_world();
    p->mutable_position()->set_x(pose.translation().x());
    p->mutable_position()->set_y(pose.translation().y());
    p->mutable_position()->set_z(pose.translation().z());
    p->mutable_orientation()->set_x(q.x());
    p->mutable_orientation()->set_y(q.y());
    p->mutable_orientation()->set_z(q.z());
    p->mutable_orientation()->set_w(q.w());
  }
  return request;
}

std::unique_ptr<grpc::ClientContext> Context() {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::seconds(60));
  return context;
}

// A still scene, frame by frame (each sent after the last answer): every
// frame is answered, the later ones reuse the first segmentation and keep
// its identities, and the stream ends OK when the client half-closes.
TEST_F(ServerTest, TrackKeepsIdentitiesOverAStillScene) {
  StartServer();
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 3);
  const std::string before = Scrape();   // the binary's tests share metrics
  ::testing::internal::CaptureStderr();  // the call's log line
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("still")));
  std::vector<v1::TrackResponse> responses;
  for (size_t t = 0; t < sequence.frames.size(); ++t) {
    ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[t], 10 + t)));
    v1::TrackResponse response;
    ASSERT_TRUE(stream->Read(&response));
    responses.push_back(response);
  }
  stream->WritesDone();
  v1::TrackResponse extra;
  EXPECT_FALSE(stream->Read(&extra));
  const grpc::Status status = stream->Finish();
  const std::string log = ::testing::internal::GetCapturedStderr();
  ASSERT_TRUE(status.ok()) << status.error_message();
  // Logged under the request id its options gave, as other calls are.
  EXPECT_THAT(log, HasSubstr("call method=Track request_id=\"still\" code=OK"));

  ASSERT_EQ(responses.size(), 3u);
  EXPECT_EQ(responses[0].request_id(), "still");
  EXPECT_FALSE(responses[0].reused());
  ASSERT_GT(responses[0].objects_size(), 0);
  for (const v1::TrackedObject& o : responses[0].objects()) {
    EXPECT_EQ(o.state(), v1::TRACK_STATE_APPEARED);
    EXPECT_GT(o.object().mask().counts_size(), 0);
  }
  for (size_t t = 1; t < responses.size(); ++t) {
    EXPECT_EQ(responses[t].sequence(), 10 + t);
    EXPECT_EQ(responses[t].frame_index(), t);
    EXPECT_TRUE(responses[t].reused());
    ASSERT_EQ(responses[t].objects_size(), responses[0].objects_size());
    for (int i = 0; i < responses[t].objects_size(); ++i) {
      EXPECT_EQ(responses[t].objects(i).track_id(),
                responses[0].objects(i).track_id());
      EXPECT_EQ(responses[t].objects(i).state(), v1::TRACK_STATE_KEPT);
    }
  }
  const std::string metrics = Scrape();
  EXPECT_EQ(MetricIncrease(before, metrics, "grpc_server_handled_total",
                           {"grpc_method=\"Track\"", "grpc_code=\"OK\""}),
            1);
  EXPECT_EQ(MetricIncrease(before, metrics, "fovea_track_frames_total",
                           {"outcome=\"reused\""}),
            2);
  // The stream is closed once the server's side of the call is done too.
  EXPECT_TRUE(WaitFor(
      [&] {
        return MetricValue(Scrape(), "fovea_track_open_streams", {}) == 0;
      },
      std::chrono::seconds(10)));
}

// An object pushed across a still scene: the frames after the first are
// segmented only in the region around it, which the response gives, and
// the objects outside it come back as they were, mask for mask.
TEST_F(ServerTest, TrackSegmentsOnlyTheRegionThatChanged) {
  StartServer();
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kPush, 5, 3);
  const std::string before = Scrape();  // the binary's tests share metrics
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("push")));
  std::vector<v1::TrackResponse> responses;
  for (size_t t = 0; t < sequence.frames.size(); ++t) {
    ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[t], t)));
    v1::TrackResponse response;
    ASSERT_TRUE(stream->Read(&response));
    responses.push_back(response);
  }
  stream->WritesDone();
  ASSERT_TRUE(stream->Finish().ok());
  ASSERT_EQ(responses.size(), 3u);
  EXPECT_FALSE(responses[0].has_segmented_region());
  const int width = sequence.frames[0].frame.frame.width();
  const int height = sequence.frames[0].frame.frame.height();
  int kept_outside = 0;
  for (size_t t = 1; t < responses.size(); ++t) {
    ASSERT_TRUE(responses[t].has_segmented_region()) << "frame " << t;
    const v1::BoundingBox& region = responses[t].segmented_region();
    EXPECT_GT(region.width(), 0u);
    EXPECT_LE(static_cast<int>(region.u() + region.width()), width);
    EXPECT_LE(static_cast<int>(region.v() + region.height()), height);
    EXPECT_LT(region.width() * region.height(),
              static_cast<uint32_t>(width * height / 2));
    for (const v1::TrackedObject& o : responses[t].objects()) {
      const v1::BoundingBox& box = o.object().box();
      const bool outside = box.u() + box.width() <= region.u() ||
                           region.u() + region.width() <= box.u() ||
                           box.v() + box.height() <= region.v() ||
                           region.v() + region.height() <= box.v();
      if (!outside) continue;
      ++kept_outside;
      EXPECT_EQ(o.state(), v1::TRACK_STATE_KEPT);
      bool same = false;
      for (const v1::TrackedObject& b : responses[t - 1].objects()) {
        if (b.track_id() != o.track_id()) continue;
        same = b.object().mask().SerializeAsString() ==
               o.object().mask().SerializeAsString();
      }
      EXPECT_TRUE(same) << "track " << o.track_id() << ", frame " << t;
    }
  }
  EXPECT_GT(kept_outside, 0);
  EXPECT_EQ(MetricIncrease(before, Scrape(), "fovea_track_frames_total",
                           {"outcome=\"region\""}),
            2);
}

// Frames that arrive while one is processed wait in one slot; a newer one
// replaces the waiting one. With the first frame's job held, frames 2-4
// arrive: 2 and 3 are skipped, 4 is answered after 1.
TEST_F(ServerTest, TrackAnswersTheFreshestFrameAndCountsTheSkipped) {
  StartServer();
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kDrift, 4, 4);
  const std::string before = Scrape();  // the binary's tests share metrics
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("fresh")));
  stage_gate_.Close();
  ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[0], 1)));
  ASSERT_TRUE(WaitFor([&] { return stage_gate_.entered() >= 1; },
                      std::chrono::seconds(30)));
  for (uint64_t t = 1; t < 4; ++t) {
    ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[t], t + 1)));
  }
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricIncrease(before, Scrape(), "fovea_track_frames_total",
                              {"outcome=\"skipped\""}) >= 2;
      },
      std::chrono::seconds(30)));
  stage_gate_.Open();
  stream->WritesDone();
  std::vector<v1::TrackResponse> responses;
  v1::TrackResponse response;
  while (stream->Read(&response)) responses.push_back(response);
  const grpc::Status status = stream->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(responses.size(), 2u);
  EXPECT_EQ(responses[0].sequence(), 1u);
  EXPECT_EQ(responses[1].sequence(), 4u);
  EXPECT_EQ(responses[1].frames_skipped(), 2u);
  EXPECT_EQ(responses[1].frame_index(), 1u);
}

// What a stream carries is checked message by message: the stream ends
// INVALID_ARGUMENT naming what was wrong, and the server goes on.
TEST_F(ServerTest, TrackNamesWhatIsWrongWithAMessage) {
  StartServer();
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 5, 2);
  struct Case {
    std::vector<v1::TrackRequest> messages;
    std::string field;
  };
  v1::TrackRequest no_frame;
  no_frame.mutable_frame()->set_sequence(1);
  v1::TrackRequest bad_pose = FrameMessage(sequence.frames[0], 1);
  bad_pose.mutable_frame()->mutable_camera_to_world()->clear_orientation();
  v1::TrackRequest bad_options = Options("x");
  bad_options.mutable_options()->set_time_budget_seconds(-1.0);
  const std::vector<Case> cases = {
      {{FrameMessage(sequence.frames[0], 1)}, "options:"},
      {{Options("a"), Options("b")}, "frame:"},
      {{Options("a"), no_frame}, "frame.frame:"},
      {{Options("a"), bad_pose}, "frame.camera_to_world.orientation"},
      {{bad_options}, "time_budget_seconds"},
  };
  for (const Case& c : cases) {
    auto context = Context();
    std::unique_ptr<Stream> stream = stub_->Track(context.get());
    for (const v1::TrackRequest& m : c.messages) stream->Write(m);
    stream->WritesDone();
    v1::TrackResponse response;
    while (stream->Read(&response)) {
    }
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << c.field;
    EXPECT_THAT(status.error_message(), HasSubstr(c.field));
  }
  v1::GetCapabilitiesResponse capabilities;
  grpc::ClientContext context;
  ASSERT_TRUE(stub_->GetCapabilities(&context, {}, &capabilities).ok());
  EXPECT_TRUE(capabilities.track());
}

// A client waiting for its answer is not idle: a frame held at a stage
// boundary for six idle timeouts is answered, and the stream ends OK. (It
// was closed as idle when a slow machine took longer than the timeout.)
TEST_F(ServerTest, TrackIsNotIdleWhileItsFrameWaitsOrRuns) {
  ServerConfig config = DefaultConfig();
  config.track_idle_timeout_s = 0.5;
  StartServer(config);
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 2);
  v1::TrackRequest frame = FrameMessage(sequence.frames[0], 1);
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("slow-answer")));
  stage_gate_.Close();
  ASSERT_TRUE(stream->Write(frame));
  ASSERT_TRUE(WaitFor([&] { return stage_gate_.entered() >= 1; },
                      std::chrono::seconds(30)));
  stream->WritesDone();  // nothing more will come from the client
  std::this_thread::sleep_for(std::chrono::seconds(3));
  stage_gate_.Open();
  v1::TrackResponse response;
  ASSERT_TRUE(stream->Read(&response));
  EXPECT_EQ(response.sequence(), 1u);
  EXPECT_FALSE(stream->Read(&response));
  const grpc::Status status = stream->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
}

// A stream is a way to hold a server: one peer opens at most
// max_track_streams_per_peer, and a stream that sends nothing is closed
// after the idle timeout.
TEST_F(ServerTest, TrackStreamsAreLimitedPerPeerAndClosedWhenIdle) {
  ServerConfig config = DefaultConfig();
  config.max_track_streams_per_peer = 1;
  config.track_idle_timeout_s = 0.5;
  StartServer(config);
  const std::string before = Scrape();
  auto first_context = Context();
  std::unique_ptr<Stream> first = stub_->Track(first_context.get());
  ASSERT_TRUE(first->Write(Options("first")));
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricValue(Scrape(), "fovea_track_open_streams", {})
                   .value_or(0) == 1;
      },
      std::chrono::seconds(10)));

  auto second_context = Context();
  std::unique_ptr<Stream> second = stub_->Track(second_context.get());
  second->Write(Options("second"));
  v1::TrackResponse response;
  EXPECT_FALSE(second->Read(&response));
  const grpc::Status refused = second->Finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(),
              HasSubstr("--max_track_streams_per_peer"));

  // The first sends nothing more: closed after about half a second.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(first->Read(&response));
  const grpc::Status idle = first->Finish();
  EXPECT_EQ(idle.error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_THAT(idle.error_message(), HasSubstr("sent nothing"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  const std::string metrics = Scrape();
  EXPECT_EQ(MetricIncrease(before, metrics, "fovea_calls_shed_total",
                           {"reason=\"idle_stream\""}),
            1);
  EXPECT_EQ(MetricIncrease(before, metrics, "fovea_calls_shed_total",
                           {"reason=\"stream_limit\""}),
            1);
  // The stream is closed once the server's side of the call is done too.
  EXPECT_TRUE(WaitFor(
      [&] {
        return MetricValue(Scrape(), "fovea_track_open_streams", {}) == 0;
      },
      std::chrono::seconds(10)));
}

// A stream whose client sends frames but never reads its answers holds no
// worker: once a write waits longer than the stall timeout the stream is
// cancelled, and another client's Detect goes through.
TEST_F(ServerTest, TrackWhoseClientNeverReadsIsCancelledAndOthersGoOn) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.stream_stall_timeout_s = 0.3;
  StartServer(config);
  std::unique_ptr<v1::Perception::Stub> lazy =
      ::fovea::server::testing::SlowReaderStub(server_->port());
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 2);
  const std::string before = Scrape();  // the binary's tests share metrics
  auto context = Context();
  std::unique_ptr<Stream> stream = lazy->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("never-reads")));
  // Still frames are answered from the last segmentation in a few ms, each
  // answer several kB of masks: the client's window fills quickly.
  for (uint64_t t = 0; t < 400; ++t) {
    if (!stream->Write(FrameMessage(sequence.frames[t % 2], t))) break;
    if (MetricIncrease(before, Scrape(), "fovea_calls_shed_total",
                       {"reason=\"stalled_stream\""}) >= 1) {
      break;
    }
  }
  ASSERT_TRUE(WaitFor(
      [&] {
        return MetricIncrease(before, Scrape(), "fovea_calls_shed_total",
                              {"reason=\"stalled_stream\""}) >= 1;
      },
      std::chrono::seconds(30)));
  v1::DetectResponse response;
  EXPECT_TRUE(
      Detect(::fovea::server::testing::MakeSyntheticRequest(1, false).request,
             &response, std::chrono::milliseconds(20000))
          .ok());
  // The server ended the stream itself.
  v1::TrackResponse ignored;
  while (stream->Read(&ignored)) {
  }
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_TRUE(WaitFor(
      [&] {
        return MetricValue(Scrape(), "fovea_track_open_streams", {}) == 0;
      },
      std::chrono::seconds(10)));
}

// Placed last: the tests above count their frames in the process's metrics.
// An open stream was admitted: its frame waits its turn in a full work
// queue instead of being skipped, so a client that sends a frame after
// each answer gets one (it would wait forever for a skipped frame's).
TEST_F(ServerTest, TrackFrameWaitsInAFullQueueAndIsAnswered) {
  ServerConfig config = DefaultConfig();
  config.concurrency = 1;
  config.queue = 0;
  StartServer(config);
  std::future<grpc::Status> running =
      StartHeldDetect(testing::MakeSyntheticRequest(1, false).request);
  ASSERT_EQ(gate_.entered(), 1);
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 2);
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("behind-a-busy-worker")));
  ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[0], 1)));
  // Queued past the queue's capacity (0), not skipped.
  ASSERT_TRUE(
      WaitFor([this] { return server_->queued_jobs() == 1; }, kCallTimeout));
  gate_.Open();
  v1::TrackResponse response;
  ASSERT_TRUE(stream->Read(&response));
  EXPECT_EQ(response.sequence(), 1u);
  EXPECT_EQ(response.frames_skipped(), 0u);
  EXPECT_GT(response.objects_size(), 0);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
  EXPECT_TRUE(running.get().ok());
}

// A connection older than --max_connection_age_s is asked to go away
// (GOAWAY), but a Track stream on it, a robot's session, goes on: calls
// in flight get the default grace, a day. (With a grace of 1 s the stream
// was cut 1.5 s after it opened; at the defaults, 5.5 minutes.)
TEST_F(ServerTest, TrackStreamOutlivesItsConnectionsAge) {
  ServerConfig config = DefaultConfig();
  config.max_connection_age_s = 0.5;
  StartServer(config);
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 2);
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->Track(context.get());
  ASSERT_TRUE(stream->Write(Options("long-session")));
  v1::TrackResponse response;
  ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[0], 1)));
  ASSERT_TRUE(stream->Read(&response));
  // Past the age (and its jitter) and what a short grace would allow.
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  ASSERT_TRUE(stream->Write(FrameMessage(sequence.frames[1], 2)));
  ASSERT_TRUE(stream->Read(&response));
  EXPECT_EQ(response.sequence(), 2u);
  stream->WritesDone();
  const grpc::Status status = stream->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
}

}  // namespace
}  // namespace fovea::server
