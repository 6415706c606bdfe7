// fovea-client's command line without a server: usage errors exit 64 and
// say what was wrong; --help lists the flags.

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/client/cli_test_util.h"

namespace fovea::client {
namespace {

using ::testing::HasSubstr;

TEST(FoveaClientCliUsageTest, NoCommandPrintsUsageAndExits64) {
  const CliRun run = RunCli("");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("usage: fovea-client"));
  EXPECT_THAT(run.err, HasSubstr("detect"));
}

TEST(FoveaClientCliUsageTest, HelpListsTheFlags) {
  const CliRun run = RunCli("--help");
  EXPECT_EQ(run.exit_code, 1) << "absl exits 1 after --help";
  const std::string text = run.out + run.err;
  for (const char* flag : {"--server", "--saliency", "--extract", "--points",
                           "--json", "--out", "--deadline_ms", "--pcd",
                           "--synthetic", "--method", "--time_budget_ms"}) {
    EXPECT_THAT(text, HasSubstr(flag));
  }
  EXPECT_THAT(text, HasSubstr("dns:///NAME:PORT"));
}

TEST(FoveaClientCliUsageTest, BadServerListIsAUsageErrorNamingTheEntry) {
  CliRun run = RunCli("--server 127.0.0.1:1,,127.0.0.1:2 health");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("entry 2"));
  EXPECT_THAT(run.err, HasSubstr("is empty"));
  run = RunCli("--server 127.0.0.1:1,fovea-b:2 detect --synthetic 1");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("dns:///fovea-b:2"));
}

TEST(FoveaClientCliUsageTest, UnknownCommandExits64) {
  const CliRun run = RunCli("--server 127.0.0.1:1 frobnicate");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("frobnicate"));
}

TEST(FoveaClientCliUsageTest, BogusSaliencyIsNamedBeforeAnyCall) {
  const CliRun run =
      RunCli("--server 127.0.0.1:1 detect --synthetic 1 --saliency ph+bogus");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("INVALID_ARGUMENT"));
  EXPECT_THAT(run.err, HasSubstr("bogus"));
}

TEST(FoveaClientCliUsageTest, TwoFrameSourcesAreRefused) {
  const CliRun run =
      RunCli("--server 127.0.0.1:1 detect --synthetic 1 --pcd x.pcd");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("exactly one frame source"));
}

TEST(FoveaClientCliUsageTest, MissingFileExits1) {
  const CliRun run = RunCli(
      "--server 127.0.0.1:1 detect --color /nonexistent/c.png --depth "
      "/nonexistent/d.png");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.err, HasSubstr("NOT_FOUND"));
}

TEST(FoveaClientCliUsageTest, NoServerIsACallFailureWithItsCode) {
  const CliRun run = RunCli("--server 127.0.0.1:1 health");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("UNAVAILABLE"));
}

TEST(FoveaClientCliUsageTest, NoReplicaUpIsUnavailable) {
  const CliRun run =
      RunCli("--server 127.0.0.1:1,127.0.0.1:2 detect --synthetic 1");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("UNAVAILABLE"));
}

}  // namespace
}  // namespace fovea::client
