#include "server/flight_recorder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <set>
#include <string>
#include <vector>

#include "core/synth/synth_scene.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/track.pb.h"
#include "server/convert.h"
#include "tests/core/testing/files.h"

namespace fovea::server {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// The frame every recorded call here carries, rendered once per process
// (the budget test's 13 renders took 4 minutes under TSan).
const synth::SynthScene& Scene() {
  static const synth::SynthScene* const kScene =
      new synth::SynthScene(synth::GenerateScene(1));
  return *kScene;
}

// A Detect call on the synthetic frame sent raw (rgb8 + 16UC1) or as
// floats; `seed` names the call.
RecordedCall DetectCall(uint64_t seed, DepthEncoding depth) {
  const synth::SynthScene& scene = Scene();
  auto request = std::make_unique<v1::DetectRequest>();
  request->set_request_id("call-" + std::to_string(seed));
  *request->mutable_frame() =
      ToProtoFrame(scene.frame.frame, depth, /*depth_scale=*/0.001);
  auto response = std::make_unique<v1::DetectResponse>();
  response->add_points()->set_u(static_cast<uint32_t>(seed));
  RecordedCall call;
  call.method = "Detect";
  call.request = std::move(request);
  call.responses.push_back(std::move(response));
  call.code = "OK";
  call.seconds = 0.02;
  return call;
}

std::vector<std::string> Records(const fs::path& dir) {
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

int64_t FileBytes(const fs::path& dir) {
  int64_t total = 0;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) total += e.file_size();
  }
  return total;
}

std::string Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A record holds the frame as PNGs (16UC1 depth in its own units, exactly),
// the request without its pixels, the responses and what the call was.
TEST(FlightRecorderTest, ARecordHoldsTheFrameAsPngsTheRequestAndTheResponses) {
  const fs::path dir = testing::FreshTestDir("recorder_");
  RecorderConfig config;
  config.dir = dir.string();
  absl::StatusOr<std::unique_ptr<FlightRecorder>> recorder =
      FlightRecorder::Start(config);
  ASSERT_TRUE(recorder.ok()) << recorder.status();
  (*recorder)->Submit(DetectCall(3, DepthEncoding::k16UC1));
  (*recorder)->Flush();
  ASSERT_THAT(Records(dir), ::testing::ElementsAre("00000001-Detect"));
  const fs::path record = dir / "00000001-Detect";
  for (const char* file : {"color.png", "depth.png", "request.json",
                           "responses.jsonl", "meta.json"}) {
    EXPECT_TRUE(fs::exists(record / file)) << file;
  }
  const std::string request = Read(record / "request.json");
  EXPECT_THAT(request, HasSubstr("\"request_id\":\"call-3\""));
  EXPECT_THAT(request, HasSubstr("\"depth_scale\":0.001"));
  EXPECT_THAT(request, ::testing::Not(HasSubstr("\"data\"")));
  EXPECT_THAT(Read(record / "meta.json"), HasSubstr("\"method\":\"Detect\""));
  EXPECT_THAT(Read(record / "responses.jsonl"), HasSubstr("\"u\":3"));
  EXPECT_EQ((*recorder)->bytes(), FileBytes(dir));
  // A float depth frame is stored at 0.1 mm.
  (*recorder)->Submit(DetectCall(4, DepthEncoding::k32FC1));
  (*recorder)->Flush();
  EXPECT_THAT(Read(dir / "00000002-Detect" / "request.json"),
              HasSubstr("\"depth_scale\":0.0001"));
}

// Over many calls the files never take more than the budget, the oldest
// go first, and a recorder started again on the folder goes on after the
// last record within its own (smaller) budget.
TEST(FlightRecorderTest, TheFolderStaysWithinItsBudgetOldestFirst) {
  const fs::path dir = testing::FreshTestDir("recorder_");
  RecorderConfig config;
  config.dir = dir.string();
  config.max_bytes = 2 << 20;  // about three records of these frames
  int64_t largest = 0;
  {
    absl::StatusOr<std::unique_ptr<FlightRecorder>> recorder =
        FlightRecorder::Start(config);
    ASSERT_TRUE(recorder.ok()) << recorder.status();
    for (uint64_t i = 1; i <= 12; ++i) {
      (*recorder)->Submit(DetectCall(i, DepthEncoding::k16UC1));
      (*recorder)->Flush();
      largest = std::max(largest, FileBytes(dir));
      ASSERT_LE(FileBytes(dir), config.max_bytes) << "after call " << i;
    }
    const std::vector<std::string> kept = Records(dir);
    ASSERT_GE(kept.size(), 2u);
    EXPECT_EQ(kept.back(), "00000012-Detect");  // the newest are kept
    EXPECT_LT(kept.size(), 12u);                // the oldest went
  }
  EXPECT_GT(largest, config.max_bytes / 2);  // the budget was used
  config.max_bytes = 1 << 20;
  absl::StatusOr<std::unique_ptr<FlightRecorder>> again =
      FlightRecorder::Start(config);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_LE(FileBytes(dir), config.max_bytes);
  (*again)->Submit(DetectCall(20, DepthEncoding::k16UC1));
  (*again)->Flush();
  EXPECT_EQ(Records(dir).back(), "00000013-Detect");
  EXPECT_LE(FileBytes(dir), config.max_bytes);
}

// Submit never waits for the writer: with the writer stuck, calls past the
// queue's room are dropped at once (and the others written afterwards).
TEST(FlightRecorderTest, SubmitNeverBlocksAndDropsWhatTheQueueCannotHold) {
  const fs::path dir = testing::FreshTestDir("recorder_");
  RecorderConfig config;
  config.dir = dir.string();
  config.max_pending = 2;
  absl::StatusOr<std::unique_ptr<FlightRecorder>> recorder =
      FlightRecorder::Start(config);
  ASSERT_TRUE(recorder.ok());
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> writes{0};
  (*recorder)->set_before_write_for_test([&] {
    writes.fetch_add(1);
    released.wait();
  });
  std::vector<RecordedCall> calls;
  for (uint64_t i = 1; i <= 6; ++i) {
    calls.push_back(DetectCall(i, DepthEncoding::k16UC1));
  }
  const auto start = std::chrono::steady_clock::now();
  for (RecordedCall& call : calls) (*recorder)->Submit(std::move(call));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  release.set_value();
  (*recorder)->Flush();
  // One being written when the others came, two queued, three dropped.
  EXPECT_LE(Records(dir).size(), 3u);
  EXPECT_GE(Records(dir).size(), 2u);
}

// A Track stream is written as it goes, in parts of track_part_frames
// frames, each in the layout `fovea-client track --frames` reads, and a
// part appears (renamed from its temporary folder) when complete.
TEST(FlightRecorderTest, AStreamIsWrittenInPartsAsItGoes) {
  const fs::path dir = testing::FreshTestDir("recorder_stream_");
  RecorderConfig config;
  config.dir = dir.string();
  config.track_part_frames = 2;
  absl::StatusOr<std::unique_ptr<FlightRecorder>> recorder =
      FlightRecorder::Start(config);
  ASSERT_TRUE(recorder.ok()) << recorder.status();
  const uint64_t stream = (*recorder)->NewStream();
  EXPECT_NE(stream, 0u);
  EXPECT_NE((*recorder)->NewStream(), stream);
  RecordedCall opening;
  opening.method = "Track";
  opening.stream = stream;
  auto options = std::make_unique<v1::TrackRequest>();
  options->mutable_options()->set_request_id("arm-camera");
  opening.request = std::move(options);
  (*recorder)->Submit(std::move(opening));
  for (int i = 1; i <= 3; ++i) {
    const synth::SynthScene& scene = Scene();
    auto frame = std::make_unique<v1::TrackRequest>();
    frame->mutable_frame()->set_sequence(static_cast<uint64_t>(10 * i));
    *frame->mutable_frame()->mutable_frame() =
        ToProtoFrame(scene.frame.frame, DepthEncoding::k16UC1, 0.001);
    auto response = std::make_unique<v1::TrackResponse>();
    response->set_sequence(static_cast<uint64_t>(10 * i));
    response->add_objects()->set_track_id(7);
    RecordedCall message;
    message.method = "Track";
    message.stream = stream;
    message.frame = std::move(frame);
    message.responses.push_back(std::move(response));
    (*recorder)->Submit(std::move(message));
  }
  (*recorder)->Flush();
  // The first part is complete; the second is being written.
  EXPECT_THAT(Records(dir),
              ::testing::ElementsAre(".tmp-00000002-Track", "00000001-Track"));
  RecordedCall end;
  end.method = "Track";
  end.stream = stream;
  end.stream_end = true;
  end.code = "CANCELLED";
  end.seconds = 1.5;
  (*recorder)->Submit(std::move(end));
  (*recorder)->Flush();
  ASSERT_THAT(Records(dir),
              ::testing::ElementsAre("00000001-Track", "00000002-Track"));
  const fs::path first = dir / "00000001-Track";
  const fs::path second = dir / "00000002-Track";
  for (const char* file : {"1_color.png", "1_depth.png", "2_color.png",
                           "2_depth.png", "request.json"}) {
    EXPECT_TRUE(fs::exists(first / file)) << file;
  }
  EXPECT_FALSE(fs::exists(first / "3_color.png"));
  EXPECT_TRUE(fs::exists(second / "1_depth.png"));
  EXPECT_FALSE(fs::exists(second / "2_depth.png"));
  EXPECT_THAT(Read(first / "request.json"), HasSubstr("arm-camera"));
  EXPECT_THAT(Read(second / "request.json"), HasSubstr("arm-camera"));
  // Frames without their pixels, answers line for line.
  const std::string frames = Read(first / "frames.jsonl");
  EXPECT_EQ(std::count(frames.begin(), frames.end(), '\n'), 2);
  EXPECT_THAT(frames, HasSubstr("\"sequence\":\"20\""));
  EXPECT_THAT(frames, ::testing::Not(HasSubstr("\"data\"")));
  const std::string responses = Read(first / "responses.jsonl");
  EXPECT_EQ(std::count(responses.begin(), responses.end(), '\n'), 2);
  EXPECT_THAT(Read(first / "meta.json"),
              HasSubstr("\"part\":0,\"frames\":2,\"frames_dropped\":0,"
                        "\"continues\":true"));
  const std::string last = Read(second / "meta.json");
  EXPECT_THAT(last, HasSubstr("\"code\":\"CANCELLED\""));
  EXPECT_THAT(last, HasSubstr("\"part\":1,\"frames\":1,"));
  EXPECT_THAT(last, HasSubstr("\"continues\":false"));
  EXPECT_EQ((*recorder)->bytes(), FileBytes(dir));
}

TEST(FlightRecorderTest, SampleKeepsThatShareEvenlyAndBadConfigIsNamed) {
  const fs::path dir = testing::FreshTestDir("recorder_");
  RecorderConfig config;
  config.dir = dir.string();
  config.sample = 0.25;
  absl::StatusOr<std::unique_ptr<FlightRecorder>> recorder =
      FlightRecorder::Start(config);
  ASSERT_TRUE(recorder.ok());
  std::vector<int> kept;
  for (int i = 1; i <= 100; ++i) {
    if ((*recorder)->ShouldRecord()) kept.push_back(i);
  }
  EXPECT_EQ(kept.size(), 25u);
  EXPECT_EQ(kept.front(), 4);
  EXPECT_EQ(kept[1] - kept[0], 4);
  config.sample = 0.0;
  EXPECT_THAT(std::string(Validate(config).message()),
              HasSubstr("record_sample"));
  config.sample = 1.0;
  config.max_bytes = 0;
  EXPECT_THAT(std::string(Validate(config).message()),
              HasSubstr("record_max_mb"));
}

}  // namespace
}  // namespace fovea::server
