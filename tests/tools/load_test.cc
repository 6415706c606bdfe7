#include "tools/bench/load.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "server/log.h"
#include "server/server.h"

namespace fovea::bench {
namespace {

// An in-process server on a free loopback port, warmed up.
std::unique_ptr<server::FoveaServer> Start(server::ServerConfig config) {
  server::SetLogLevel(server::LogLevel::kWarn);
  config.listen = "127.0.0.1:0";
  absl::StatusOr<std::unique_ptr<server::FoveaServer>> started =
      server::FoveaServer::Start(std::move(config));
  EXPECT_TRUE(started.ok()) << started.status();
  if (!started.ok()) return nullptr;
  for (int i = 0; i < 6000 && !(*started)->warmed_up(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return *std::move(started);
}

TEST(LoadTest, EveryCallIsCountedByCodeWithLatencies) {
  server::ServerConfig config;
  config.concurrency = 2;
  config.queue = 8;
  std::unique_ptr<server::FoveaServer> s = Start(config);
  ASSERT_NE(s, nullptr);
  LoadOptions options;
  options.server = "127.0.0.1:" + std::to_string(s->port());
  options.clients = 2;
  options.requests = 6;
  options.rpc = "segment";
  absl::StatusOr<LoadReport> report = RunLoad(options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->calls, 6);
  EXPECT_EQ(report->codes["OK"], 6);
  EXPECT_GT(report->p50_ms, 0.0);
  EXPECT_GE(report->p99_ms, report->p50_ms);
  EXPECT_GT(report->first_object_p50_ms, 0.0);
  EXPECT_GT(report->throughput, 0.0);
}

TEST(LoadTest, AListOfReplicasSpreadsTheCalls) {
  std::atomic<int> jobs[2] = {0, 0};
  std::unique_ptr<server::FoveaServer> servers[2];
  std::string list;
  for (int i = 0; i < 2; ++i) {
    server::ServerConfig config;
    config.before_detect_job = [&jobs, i] { jobs[i].fetch_add(1); };
    servers[i] = Start(config);
    ASSERT_NE(servers[i], nullptr);
    absl::StrAppend(&list, i == 0 ? "" : ",", "127.0.0.1:", servers[i]->port());
  }
  LoadOptions options;
  options.server = list;
  options.clients = 2;
  options.requests = 20;
  absl::StatusOr<LoadReport> report = RunLoad(options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->codes["OK"], 20);
  EXPECT_GT(jobs[0].load(), 0);
  EXPECT_GT(jobs[1].load(), 0);
  EXPECT_EQ(jobs[0].load() + jobs[1].load(), 20);
}

TEST(LoadTest, AFullQueueAnswersResourceExhaustedNotACollapse) {
  server::ServerConfig config;
  config.concurrency = 1;
  config.queue = 0;
  // Keep the one worker busy long enough for the other clients to arrive.
  config.before_detect_job = [] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  };
  std::unique_ptr<server::FoveaServer> s = Start(config);
  ASSERT_NE(s, nullptr);
  LoadOptions options;
  options.server = "127.0.0.1:" + std::to_string(s->port());
  options.clients = 6;
  options.requests = 6;
  absl::StatusOr<LoadReport> report = RunLoad(options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->calls, 6);
  EXPECT_GE(report->codes["OK"], 1);
  EXPECT_GE(report->codes["ResourceExhausted"], 1);
  EXPECT_EQ(report->codes["OK"] + report->codes["ResourceExhausted"], 6);
}

// Over a fixed time, clients that back off after a refusal: goodput is the
// OK calls over that time, refusals are counted and timed, and backing off
// keeps them few (calling again at once, three waiting clients would be
// refused thousands of times in 1.5 s).
TEST(LoadTest, FixedTimeWithBackoffCountsGoodputAndFewRefusals) {
  server::ServerConfig config;
  config.concurrency = 1;
  config.queue = 0;
  config.before_detect_job = [] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  };
  std::unique_ptr<server::FoveaServer> s = Start(config);
  ASSERT_NE(s, nullptr);
  LoadOptions options;
  options.server = "127.0.0.1:" + std::to_string(s->port());
  options.clients = 4;
  options.requests = 1;  // no limit with a duration
  options.duration_seconds = 1.5;
  options.backoff = true;
  absl::StatusOr<LoadReport> report = RunLoad(options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_GE(report->seconds, 1.5);
  EXPECT_GE(report->ok, 1);  // a handful here; fewer under a sanitizer
  EXPECT_EQ(report->ok, report->codes["OK"]);
  EXPECT_NEAR(report->goodput, report->ok / report->seconds, 1e-9);
  EXPECT_GE(report->refused, 1);
  EXPECT_LT(report->refused, 100);
  EXPECT_EQ(report->refused, report->codes["ResourceExhausted"]);
  EXPECT_GT(report->refusal_p50_ms, 0.0);
  EXPECT_GE(report->refusal_p99_ms, report->refusal_p50_ms);
}

// rpc "track": a stream's answered frames are the OK calls.
TEST(LoadTest, TrackCountsTheFramesAnswered) {
  std::unique_ptr<server::FoveaServer> s = Start(server::ServerConfig());
  ASSERT_NE(s, nullptr);
  LoadOptions options;
  options.server = "127.0.0.1:" + std::to_string(s->port());
  options.clients = 1;
  options.rpc = "track";
  options.duration_seconds = 1.0;
  absl::StatusOr<LoadReport> report = RunLoad(options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_GE(report->ok, 1);  // each frame is segmented: a few a second here
  EXPECT_EQ(report->calls, report->ok);  // nothing refused, nothing failed
  EXPECT_GT(report->p50_ms, 0.0);
}

TEST(LoadTest, OnlyLoopbackAndSaneNumbers) {
  LoadOptions options;
  options.server = "10.1.2.3:50051";
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.server = "127.0.0.1:1,10.1.2.3:50051";
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.server = "127.0.0.1:1,,127.0.0.1:2";
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.server = "127.0.0.1:1";
  options.clients = 0;
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.clients = 1;
  options.rpc = "nope";
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.rpc = "detect";
  options.duration_seconds = -1;
  EXPECT_EQ(RunLoad(options).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea::bench
