// fovea-eval replay against a live server: what the flight recorder kept
// replays unchanged on the same server, and a record whose answer no
// longer matches is reported changed (exit 3 with --fail_on_change).
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "server/log.h"
#include "server/server.h"
#include "tests/core/testing/files.h"
#include "tests/server/test_util.h"
#include "tests/testing/run_command.h"

namespace fovea::eval {
namespace {

namespace fs = std::filesystem;

std::vector<nlohmann::json> JsonLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '{')
      lines.push_back(nlohmann::json::parse(line));
  }
  return lines;
}

TEST(ReplayTest, RecordedCallsReplayUnchangedAndAChangedAnswerIsReported) {
  server::SetLogLevel(server::LogLevel::kWarn);
  const fs::path dir = testing::FreshTestDir("replay_");
  server::ServerConfig config;
  config.listen = "127.0.0.1:0";
  config.concurrency = 1;
  config.record_dir = (dir / "records").string();
  config.record_max_bytes = 64 << 20;
  absl::StatusOr<std::unique_ptr<server::FoveaServer>> s =
      server::FoveaServer::Start(config);
  ASSERT_TRUE(s.ok()) << s.status();
  for (int i = 0; i < 6000 && !(*s)->warmed_up(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::string target = "127.0.0.1:" + std::to_string((*s)->port());
  auto stub = v1::Perception::NewStub(
      grpc::CreateChannel(target, grpc::InsecureChannelCredentials()));
  {
    grpc::ClientContext context;
    v1::DetectResponse response;
    ASSERT_TRUE(
        stub->Detect(&context,
                     server::testing::MakeSyntheticRequest(1, true).request,
                     &response)
            .ok());
  }
  {
    v1::SegmentRequest request;
    *request.mutable_frame() =
        server::testing::MakeSyntheticRequest(2, true).request.frame();
    grpc::ClientContext context;
    auto reader = stub->Segment(&context, request);
    v1::SegmentResponse message;
    while (reader->Read(&message)) {
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  {
    // A Track stream of three frames of a still scene, lockstep.
    grpc::ClientContext context;
    auto stream = stub->Track(&context);
    v1::TrackRequest opening;
    opening.mutable_options()->set_request_id("replayed-stream");
    ASSERT_TRUE(stream->Write(opening));
    v1::TrackResponse response;
    for (int i = 0; i < 3; ++i) {
      v1::TrackRequest frame;
      frame.mutable_frame()->set_sequence(static_cast<uint64_t>(i));
      *frame.mutable_frame()->mutable_frame() =
          server::testing::MakeSyntheticRequest(3, true).request.frame();
      ASSERT_TRUE(stream->Write(frame));
      ASSERT_TRUE(stream->Read(&response));
      ASSERT_GE(response.objects_size(), 1);
    }
    stream->WritesDone();
    ASSERT_TRUE(stream->Finish().ok());
  }
  // A call is handed to the recorder when the server is done with it,
  // which can be after the client has its status, and the stream's record
  // is numbered when it opened: wait for the three records (each appears
  // whole), at most 30 s on a loaded machine, and find them by method.
  const fs::path records = dir / "records";
  std::map<std::string, fs::path> by_method;
  for (int i = 0; i < 3000 && by_method.size() < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    by_method.clear();
    for (const fs::directory_entry& e : fs::directory_iterator(records)) {
      const std::string name = e.path().filename().string();
      if (name[0] == '.') continue;  // being written
      by_method[name.substr(name.find('-') + 1)] = e.path();
    }
  }
  (*s)->recorder()->Flush();
  ASSERT_EQ(by_method.size(), 3u);
  // A new server (not recording) is what the calls are replayed on.
  config.record_dir.clear();
  absl::StatusOr<std::unique_ptr<server::FoveaServer>> fresh =
      server::FoveaServer::Start(config);
  ASSERT_TRUE(fresh.ok()) << fresh.status();
  for (int i = 0; i < 6000 && !(*fresh)->warmed_up(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::string replay_target =
      "127.0.0.1:" + std::to_string((*fresh)->port());

  const std::string replay = std::string(FOVEA_EVAL_BIN) + " replay " +
                             records.string() + " --server " + replay_target;
  ::fovea::testing::CommandRun run =
      ::fovea::testing::RunCommand(replay + " --json --fail_on_change");
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  std::vector<nlohmann::json> all = JsonLines(run.out);
  ASSERT_EQ(all.size(), 4u) << run.out;
  // The record lines by method, then the summary.
  const auto ByMethod = [](const std::vector<nlohmann::json>& found) {
    std::vector<nlohmann::json> out(4);
    for (const nlohmann::json& line : found) {
      const std::string method = line.value("method", "");
      out[method == "Detect"    ? 0
          : method == "Segment" ? 1
          : method == "Track"   ? 2
                                : 3] = line;
    }
    return out;
  };
  std::vector<nlohmann::json> lines = ByMethod(all);
  EXPECT_EQ(lines[0]["method"], "Detect");
  EXPECT_EQ(lines[0]["max_shift_px"], 0.0);  // 16UC1 frames replay exactly
  EXPECT_EQ(lines[0]["lost"], 0);
  EXPECT_EQ(lines[1]["method"], "Segment");
  EXPECT_GE(lines[1]["recorded"].get<int>(), 2);
  EXPECT_EQ(lines[1]["mean_iou"], 1.0);
  EXPECT_EQ(lines[2]["method"], "Track");
  EXPECT_EQ(lines[2]["frames"], 3);
  EXPECT_EQ(lines[2]["frames_now"], 3);
  EXPECT_GE(lines[2]["recorded"].get<int>(), 3);  // objects over 3 frames
  EXPECT_EQ(lines[2]["mean_iou"], 1.0);
  EXPECT_EQ(lines[2]["id_switches"], 0);
  EXPECT_EQ(lines.back()["replayed"], 3);
  EXPECT_EQ(lines.back()["changed"], 0);

  // The recorded stream said one object fewer (as an older server might
  // have): the replay finds it, and --fail_on_change says so.
  const fs::path jsonl = by_method["Segment"] / "responses.jsonl";
  std::ifstream in(jsonl);
  std::vector<std::string> kept;
  bool dropped = false;
  for (std::string line; std::getline(in, line);) {
    if (!dropped && line.find("\"object\"") != std::string::npos) {
      dropped = true;
      continue;
    }
    kept.push_back(line);
  }
  in.close();
  std::ofstream out(jsonl, std::ios::trunc);
  for (const std::string& line : kept) out << line << "\n";
  out.close();
  run = ::fovea::testing::RunCommand(replay + " --json --fail_on_change");
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  lines = ByMethod(JsonLines(run.out));
  EXPECT_EQ(lines[1]["found"], 1);
  EXPECT_EQ(lines[1]["changed"], true);
  EXPECT_EQ(lines.back()["changed"], 1);
  // The recorded stream's last frame gave its objects other ids (as a
  // tracker that lost them would have): the replay counts the switches.
  const fs::path track_jsonl = by_method["Track"] / "responses.jsonl";
  std::ifstream track_in(track_jsonl);
  std::vector<nlohmann::json> answers;
  for (std::string line; std::getline(track_in, line);) {
    answers.push_back(nlohmann::json::parse(line));
  }
  track_in.close();
  ASSERT_EQ(answers.size(), 3u);
  for (auto& object : answers[2]["objects"]) {
    object["track_id"] = std::to_string(
        std::stoull(object["track_id"].get<std::string>()) + 100);
  }
  std::ofstream track_out(track_jsonl, std::ios::trunc);
  for (const nlohmann::json& answer : answers)
    track_out << answer.dump() << "\n";
  track_out.close();
  run = ::fovea::testing::RunCommand(replay + " --json --fail_on_change");
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  lines = ByMethod(JsonLines(run.out));
  EXPECT_EQ(lines[2]["id_switches"], answers[2]["objects"].size());
  EXPECT_EQ(lines[2]["changed"], true);
  // Without --fail_on_change the table is printed and the exit code is 0.
  run = ::fovea::testing::RunCommand(replay);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, ::testing::HasSubstr("CHANGED"));
  // No server or folder: a usage error naming what is missing.
  run = ::fovea::testing::RunCommand(std::string(FOVEA_EVAL_BIN) + " replay " +
                                     records.string());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, ::testing::HasSubstr("--server"));
}

}  // namespace
}  // namespace fovea::eval
