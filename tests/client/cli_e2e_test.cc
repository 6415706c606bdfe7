// fovea-client against an in-process fovea server on a loopback port.

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "client/fovea_client.h"
#include "core/synth/sequence.h"
#include "fovea/v1/detect.pb.h"
#include "gmock/gmock.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "proto/enum_names.h"
#include "server/server.h"
#include "tests/client/cli_test_util.h"

namespace fovea::client {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

constexpr absl::Duration kServingWait = absl::Seconds(60);

class FoveaClientCliE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server::ServerConfig config;
    config.listen = "127.0.0.1:0";
    config.metrics_listen = "";
    config.concurrency = 1;
    absl::StatusOr<std::unique_ptr<server::FoveaServer>> started =
        server::FoveaServer::Start(config);
    ASSERT_TRUE(started.ok()) << started.status();
    server_ = started->release();
    address_ = absl::StrCat("127.0.0.1:", server_->port());

    // Bounded wait for SERVING (the server warms up first).
    absl::StatusOr<std::unique_ptr<FoveaClient>> client =
        FoveaClient::Connect(address_);
    ASSERT_TRUE(client.ok()) << client.status();
    const absl::Time give_up = absl::Now() + kServingWait;
    while (absl::Now() < give_up) {
      absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus> s =
          (*client)->Health("", absl::Seconds(1));
      if (s.ok() && *s == grpc::health::v1::HealthCheckResponse::SERVING) {
        return;
      }
      absl::SleepFor(absl::Milliseconds(50));
    }
    FAIL() << "server not SERVING after " << kServingWait;
  }

  static void TearDownTestSuite() {
    if (server_ != nullptr) server_->Shutdown(absl::Seconds(5));
    delete server_;
    server_ = nullptr;
  }

  static server::FoveaServer* server_;  // owned by the suite
  static std::string address_;
};

server::FoveaServer* FoveaClientCliE2eTest::server_ = nullptr;
std::string FoveaClientCliE2eTest::address_;

TEST_F(FoveaClientCliE2eTest, HealthPrintsServing) {
  const CliRun run = RunCli(absl::StrCat("--server ", address_, " health"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "SERVING\n");
}

// Port 1 on loopback has no listener: round robin skips that replica.
TEST_F(FoveaClientCliE2eTest, ReplicaListSkipsOneThatIsDown) {
  const std::string servers = absl::StrCat("127.0.0.1:1,", address_);
  CliRun run = RunCli(absl::StrCat("--server ", servers, " health"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "SERVING\n");
  run = RunCli(
      absl::StrCat("--server ", servers, " detect --synthetic 3 --json"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  run = RunCli(absl::StrCat("--server ", servers,
                            " segment --synthetic 3 --max_objects 1 --json"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

TEST_F(FoveaClientCliE2eTest, DetectSyntheticJsonHasPoints) {
  const CliRun run = RunCli(
      absl::StrCat("--server ", address_, " detect --synthetic 3 --json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<std::string> lines =
      absl::StrSplit(run.out, '\n', absl::SkipEmpty());
  ASSERT_EQ(lines.size(), 1u) << "one JSON object per line:\n" << run.out;
  fovea::v1::DetectResponse response;
  const auto parsed =
      google::protobuf::util::JsonStringToMessage(lines[0], &response);
  ASSERT_TRUE(parsed.ok()) << parsed.message() << "\n" << lines[0];
  ASSERT_GT(response.points_size(), 0);
  EXPECT_EQ(response.points(0).rank(), 0u);
  EXPECT_LT(response.points(0).u(), 640u);
  EXPECT_LT(response.points(0).v(), 480u);
}

// Every operator of the wire contract, by the name fovea-client takes for
// it (the proto value's name in lower case), runs through the CLI: the
// response's timings hold that operator's stage. The two top-down cues
// get their flags.
TEST_F(FoveaClientCliE2eTest, EveryOperatorRunsFromTheCommandLine) {
  const google::protobuf::EnumDescriptor* values =
      fovea::v1::SaliencyOperator_descriptor();
  int operators = 0;
  for (int i = 0; i < values->value_count(); ++i) {
    if (values->value(i)->number() == 0) continue;
    const std::string name = fovea::v1::ShortEnumName(*values->value(i));
    std::string extra;
    if (name == "target_color") extra = " --target_color 200,30,30";
    if (name == "location_prior") {
      extra = " --location_prior 320,240 --location_sigma 60";
    }
    const CliRun run = RunCli(absl::StrCat("--server ", address_,
                                           " detect --synthetic 3 --json "
                                           "--saliency ",
                                           name, extra));
    ASSERT_EQ(run.exit_code, 0) << name << ": " << run.err;
    fovea::v1::DetectResponse response;
    ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(
                    std::string(absl::StripAsciiWhitespace(run.out)), &response)
                    .ok())
        << name << ": " << run.out;
    bool timed = false;
    for (const fovea::v1::StageTiming& timing : response.timings()) {
      timed |= timing.stage() == "saliency." + name;
    }
    EXPECT_TRUE(timed) << name << " did not run:\n" << run.out;
    ++operators;
  }
  EXPECT_GE(operators, 10);

  // A cue operator without its cue is the server's INVALID_ARGUMENT; a
  // malformed cue is a usage error naming the flag.
  CliRun run = RunCli(absl::StrCat("--server ", address_,
                                   " detect --synthetic 3 --saliency "
                                   "target_color"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("target_color_rgb"));
  run = RunCli(absl::StrCat("--server ", address_,
                            " detect --synthetic 3 --saliency target_color "
                            "--target_color 300,0,0"));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.err, HasSubstr("--target_color"));
  run = RunCli(absl::StrCat("--server ", address_,
                            " detect --synthetic 3 --saliency location_prior "
                            "--location_prior 320"));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.err, HasSubstr("--location_prior"));
}

TEST_F(FoveaClientCliE2eTest, SplitEdgesFlagIsSentEitherWay) {
  for (const char* value : {"true", "false"}) {
    const CliRun run = RunCli(
        absl::StrCat("--server ", address_,
                     " detect --synthetic 3 --json --split_edges=", value));
    ASSERT_EQ(run.exit_code, 0) << value << ": " << run.err;
    EXPECT_THAT(run.out, HasSubstr("\"points\"")) << value;
  }
  const CliRun bad = RunCli(absl::StrCat(
      "--server ", address_, " detect --synthetic 3 --split_edges=maybe"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.err, HasSubstr("split_edges"));
}

TEST_F(FoveaClientCliE2eTest, FailedCallPrintsCodeAndExits2) {
  // A negative focal length is bad input the server must refuse.
  const CliRun run = RunCli(
      absl::StrCat("--server ", address_, " detect --synthetic 3 --fx=-1"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("INVALID_ARGUMENT"));
}

TEST_F(FoveaClientCliE2eTest, SegmentStreamsObjectsAndWritesEachMask) {
  const std::string out =
      ::testing::TempDir() + "/segment_cli_" + std::to_string(::getpid());
  const CliRun run = RunCli(absl::StrCat("--server ", address_,
                                         " segment --synthetic 3 --out ", out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("object 0:"));
  EXPECT_THAT(run.out, HasSubstr("last: DONE"));
  EXPECT_TRUE(std::filesystem::exists(out + "/mask_0.png"));
  EXPECT_TRUE(std::filesystem::exists(out + "/overlay.png"));
  EXPECT_TRUE(std::filesystem::exists(out + "/responses.jsonl"));
  std::filesystem::remove_all(out);
}

// track --frames DIR: one's own frames in a folder, in numeric order (2
// before 10), one JSON line per processed frame with each object's
// track_id and mask; a still scene keeps its identities.
TEST_F(FoveaClientCliE2eTest, TrackSendsAFolderOfFramesAndKeepsIdentities) {
  const std::string dir =
      ::testing::TempDir() + "/track_cli_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const synth::Sequence sequence =
      synth::GenerateSequence(synth::SequenceKind::kStatic, 3, 3);
  const int numbers[] = {2, 10, 31};
  for (int i = 0; i < 3; ++i) {
    const RgbdFrame& frame = sequence.frames[i].frame.frame;
    cv::Mat bgr;
    cv::cvtColor(frame.color, bgr, cv::COLOR_RGB2BGR);
    cv::Mat millimetres;
    frame.depth.convertTo(millimetres, CV_16UC1, 1000.0);  // NaN -> 0
    ASSERT_TRUE(
        cv::imwrite(absl::StrCat(dir, "/", numbers[i], "_color.png"), bgr));
    ASSERT_TRUE(cv::imwrite(absl::StrCat(dir, "/", numbers[i], "_depth.png"),
                            millimetres));
  }
  const CliRun run = RunCli(
      absl::StrCat("--server ", address_, " track --frames ", dir, " --json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<std::string> lines =
      absl::StrSplit(run.out, '\n', absl::SkipEmpty());
  ASSERT_EQ(lines.size(), 3u) << run.out;
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_THAT(lines[i], HasSubstr(absl::StrCat("\"sequence\":\"", i, "\"")));
    EXPECT_THAT(lines[i], HasSubstr("\"trackId\":\"1\""));
    EXPECT_THAT(lines[i], HasSubstr("\"counts\""));  // the RLE mask
  }
  EXPECT_THAT(lines[0], HasSubstr("TRACK_STATE_APPEARED"));
  EXPECT_THAT(lines[2], HasSubstr("TRACK_STATE_KEPT"));
  EXPECT_THAT(lines[2], HasSubstr("\"reused\":true"));

  const CliRun text =
      RunCli(absl::StrCat("--server ", address_, " track --frames ", dir));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("#1 appeared"));
  EXPECT_THAT(text.out, HasSubstr("3 of 3 frames answered"));

  const CliRun empty = RunCli(
      absl::StrCat("--server ", address_, " track --frames ", dir, "/none"));
  EXPECT_EQ(empty.exit_code, 64);
  EXPECT_THAT(empty.err, HasSubstr("--frames"));
  std::filesystem::remove_all(dir);
}

TEST_F(FoveaClientCliE2eTest,
       SegmentIncrementalStreamsObjectsAndStopsOnBudget) {
  const std::string out =
      ::testing::TempDir() + "/segment_inc_cli_" + std::to_string(::getpid());
  const CliRun run = RunCli(absl::StrCat(
      "--server ", address_,
      " segment-incremental --synthetic 3 --max_objects 2 --out ", out));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("object 1:"));
  EXPECT_THAT(run.out, HasSubstr("last: MAX_OBJECTS, 2 objects"));
  EXPECT_TRUE(std::filesystem::exists(out + "/mask_1.png"));
  std::filesystem::remove_all(out);
}

TEST_F(FoveaClientCliE2eTest, SegmentSeedsAreSentAndBadOnesAreUsageErrors) {
  // A seed in the corner sees no object: the stream ends with none.
  const CliRun corner = RunCli(absl::StrCat(
      "--server ", address_, " segment --synthetic 3 --seeds 2,2"));
  ASSERT_EQ(corner.exit_code, 0) << corner.err;
  EXPECT_THAT(corner.out, HasSubstr("attention points 1: (2,2)"));
  EXPECT_THAT(corner.out, HasSubstr("0 objects"));
  const CliRun bad = RunCli(absl::StrCat(
      "--server ", address_, " segment --synthetic 3 --seeds '2;x'"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.err, HasSubstr("seeds"));
}

}  // namespace
}  // namespace fovea::client
