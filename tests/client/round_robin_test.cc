// FoveaClient over three in-process replicas on loopback ports: calls are
// spread round robin, a replica that drains stops getting new calls, and
// a replica that stops mid-run loses no call (the ones in flight on it
// fail with UNAVAILABLE and are retried on the others).

#include <array>
#include <atomic>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "client/fovea_client.h"
#include "core/base/mutex.h"
#include "gtest/gtest.h"
#include "server/server.h"
#include "tests/server/server_fixture.h"
#include "tests/server/test_util.h"

namespace fovea::client {
namespace {

using server::testing::HealthStatus;
using server::testing::MakeSyntheticRequest;
using server::testing::WaitFor;

constexpr int kReplicas = 3;
constexpr int kThreads = 3;  // callers of the load
constexpr absl::Duration kCallDeadline = absl::Seconds(30);
constexpr auto kWait = std::chrono::seconds(60);  // bound of every poll

// Counts the passes through a server test hook (a Detect job starting, a
// stage boundary) and, once holding, keeps each later pass there until
// released.
class Checkpoint {
 public:
  // The hook.
  void Pass() {
    MutexLock lock(&mu_);
    ++passed_;
    if (hold_from_ == 0 || passed_ < hold_from_) return;
    ++held_;
    mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
      return hold_from_ == 0;
    });
  }
  // Holds every pass from now on.
  void Hold() {
    MutexLock lock(&mu_);
    hold_from_ = passed_ + 1;
  }
  // Holds the `n`-th pass from now (1-based) and every later one.
  void HoldFrom(int n) {
    MutexLock lock(&mu_);
    hold_from_ = passed_ + n;
  }
  void Release() {
    MutexLock lock(&mu_);
    hold_from_ = 0;
  }
  int passed() const {
    MutexLock lock(&mu_);
    return passed_;
  }
  // Passes that were held, released or not.
  int held() const {
    MutexLock lock(&mu_);
    return held_;
  }

 private:
  mutable Mutex mu_;
  int hold_from_ ABSL_GUARDED_BY(mu_) = 0;  // 0: not holding
  int passed_ ABSL_GUARDED_BY(mu_) = 0;
  int held_ ABSL_GUARDED_BY(mu_) = 0;
};

// One in-process server and its hooks.
struct Replica {
  std::unique_ptr<server::FoveaServer> server;
  std::string address;
  Checkpoint jobs;    // Detect jobs starting (calls that reached a worker)
  Checkpoint stages;  // stage boundaries of every call
};

std::string Describe(const std::array<int, kReplicas>& jobs) {
  return absl::StrJoin(jobs, " / ");
}

// Closed-loop load from a few threads: each repeats a call until stopped
// and keeps every call's status and the phases it started and ended in.
class Load {
 public:
  struct Call {
    absl::Status status;
    int started = 0;  // phase
    int ended = 0;
  };

  Load(int threads, const std::function<absl::Status()>& call) {
    done_.resize(threads, 0);
    for (int t = 0; t < threads; ++t) {
      threads_.emplace_back([this, t, call] {
        while (!stop_.load()) {
          const int started = phase_.load();
          absl::Status status = call();
          MutexLock lock(&mu_);
          calls_.push_back({std::move(status), started, phase_.load()});
          if (started == phase_.load()) ++done_[t];
        }
      });
    }
  }
  ~Load() { Stop(); }

  // Starts the next phase (the first is 0).
  void NextPhase() {
    MutexLock lock(&mu_);
    phase_.fetch_add(1);
    std::fill(done_.begin(), done_.end(), 0);
  }
  // True when every thread finished at least `n` calls it started in the
  // current phase (so none is stuck in an older call).
  bool EachThreadDid(int n) const {
    MutexLock lock(&mu_);
    for (int done : done_) {
      if (done < n) return false;
    }
    return true;
  }
  void Stop() {
    stop_.store(true);
    for (std::thread& thread : threads_) {
      if (thread.joinable()) thread.join();
    }
  }
  std::vector<Call> calls() const {
    MutexLock lock(&mu_);
    return calls_;
  }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<int> phase_{0};
  mutable Mutex mu_;
  std::vector<Call> calls_ ABSL_GUARDED_BY(mu_);
  std::vector<int> done_ ABSL_GUARDED_BY(mu_);  // per thread, this phase
  std::vector<std::thread> threads_;
};

// What StopOneMidRun saw. Phases of its Load: 0 before the stop, 1 from
// the stop until the replica refuses connections, 2 after.
struct StopRun {
  std::vector<Load::Call> calls;  // in the order they returned
  int held = 0;  // calls in a job on the stopped replica when it stopped
  std::array<int, kReplicas> at_stop{};  // jobs per replica, refused
  std::array<int, kReplicas> after{};    // ... once every caller went on
  std::array<int, kReplicas> at_end{};   // ... once every call returned
};

int Failed(const std::vector<Load::Call>& calls) {
  int failed = 0;
  for (const Load::Call& call : calls) failed += !call.status.ok();
  return failed;
}

// One Segment call through a client, on its own thread.
class StreamCall {
 public:
  StreamCall(FoveaClient& client, const fovea::v1::SegmentRequest& request)
      : thread_([this, &client, request] {
          absl::Status status =
              client.Segment(request, kCallDeadline,
                             [this](const fovea::v1::SegmentResponse& message) {
                               MutexLock lock(&mu_);
                               messages_.push_back(message);
                             });
          MutexLock lock(&mu_);
          status_ = std::move(status);
          done_ = true;
        }) {}
  ~StreamCall() { thread_.join(); }

  bool done() const {
    MutexLock lock(&mu_);
    return done_;
  }
  // The stream's final status, once done.
  absl::Status status() const {
    MutexLock lock(&mu_);
    return status_;
  }
  std::vector<fovea::v1::SegmentResponse> messages() const {
    MutexLock lock(&mu_);
    return messages_;
  }

 private:
  mutable Mutex mu_;
  std::vector<fovea::v1::SegmentResponse> messages_ ABSL_GUARDED_BY(mu_);
  absl::Status status_ ABSL_GUARDED_BY(mu_);
  bool done_ ABSL_GUARDED_BY(mu_) = false;
  std::thread thread_;  // last: starts once the rest is built
};

// Messages of each kind in a stream: those with attention points (the
// first), with `last` set.
int PointsMessages(const std::vector<fovea::v1::SegmentResponse>& messages) {
  int count = 0;
  for (const auto& message : messages) {
    count += message.attention_points_size() > 0;
  }
  return count;
}
int LastMessages(const std::vector<fovea::v1::SegmentResponse>& messages) {
  int count = 0;
  for (const auto& message : messages) count += message.last();
  return count;
}

class RoundRobinTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (Replica& replica : replicas_) {
      server::ServerConfig config;
      config.listen = "127.0.0.1:0";  // the kernel picks; see server_fixture.cc
      config.concurrency = 2;
      config.queue = 4;
      config.warm_up = false;  // SERVING at once
      config.before_detect_job = [&replica] { replica.jobs.Pass(); };
      config.at_stage_boundary = [&replica] { replica.stages.Pass(); };
      absl::StatusOr<std::unique_ptr<server::FoveaServer>> started =
          server::FoveaServer::Start(std::move(config));
      ASSERT_TRUE(started.ok()) << started.status();
      replica.server = *std::move(started);
      replica.address = absl::StrCat("127.0.0.1:", replica.server->port());
    }
    for (Replica& replica : replicas_) {
      std::shared_ptr<grpc::Channel> channel = grpc::CreateChannel(
          replica.address, grpc::InsecureChannelCredentials());
      ASSERT_TRUE(WaitFor(
          [&] {
            return HealthStatus(channel, "fovea.v1.Perception") == "SERVING";
          },
          kWait))
          << replica.address;
    }
    absl::StatusOr<std::unique_ptr<FoveaClient>> client =
        FoveaClient::Connect(Servers());
    ASSERT_TRUE(client.ok()) << client.status();
    client_ = *std::move(client);
    request_ = MakeSyntheticRequest(3, /*depth_16uc1=*/true).request;
  }

  void TearDown() override {
    for (Replica& replica : replicas_) {
      replica.jobs.Release();
      replica.stages.Release();
      if (replica.server != nullptr) replica.server->Shutdown(absl::Seconds(5));
    }
  }

  std::array<int, kReplicas> Jobs() const {
    std::array<int, kReplicas> jobs;
    for (int i = 0; i < kReplicas; ++i) jobs[i] = replicas_[i].jobs.passed();
    return jobs;
  }

  // The three addresses, comma-separated.
  std::string Servers() const {
    std::vector<std::string> addresses;
    for (const Replica& replica : replicas_) {
      addresses.push_back(replica.address);
    }
    return absl::StrJoin(addresses, ",");
  }

  absl::Status Detect() {
    return client_->Detect(request_, kCallDeadline).status();
  }

  // Drives Detect from kThreads threads through a client with
  // `max_attempts` until every replica has served two calls; then holds
  // the calls that reach replica 1 until one is in a job there, stops it
  // with no grace (what it holds is cancelled, its connections close) and
  // goes on until each thread made three more calls.
  StopRun StopOneMidRun(int max_attempts) {
    StopRun run;
    ClientOptions options;
    options.max_attempts = max_attempts;
    absl::StatusOr<std::unique_ptr<FoveaClient>> client =
        FoveaClient::Connect(Servers(), options);
    EXPECT_TRUE(client.ok()) << client.status();
    if (!client.ok()) return run;
    Replica& stopped = replicas_[1];
    Load load(kThreads, [&] {
      return (*client)->Detect(request_, kCallDeadline).status();
    });

    EXPECT_TRUE(WaitFor(
        [&] {
          for (const Replica& replica : replicas_) {
            if (replica.jobs.passed() < 2) return false;
          }
          return true;
        },
        kWait))
        << "not every replica served; jobs " << Describe(Jobs());

    stopped.jobs.Hold();
    EXPECT_TRUE(WaitFor([&] { return stopped.jobs.held() > 0; }, kWait));
    load.NextPhase();
    // Shutdown waits for the held jobs, which go on once released.
    std::thread stopper(
        [&] { stopped.server->Shutdown(absl::ZeroDuration()); });
    std::shared_ptr<grpc::Channel> direct = grpc::CreateChannel(
        stopped.address, grpc::InsecureChannelCredentials());
    EXPECT_TRUE(WaitFor([&] { return HealthStatus(direct, "") == "14"; },
                        kWait))  // UNAVAILABLE
        << "the stopped replica still accepts connections";
    run.at_stop = Jobs();

    load.NextPhase();
    EXPECT_TRUE(WaitFor([&] { return load.EachThreadDid(3); }, kWait))
        << "a caller is stuck; jobs " << Describe(Jobs());
    run.after = Jobs();
    load.Stop();
    run.at_end = Jobs();
    stopped.jobs.Release();
    stopper.join();
    run.held = stopped.jobs.held();
    run.calls = load.calls();
    std::cout << "max_attempts " << max_attempts << ": " << run.calls.size()
              << " calls, " << Failed(run.calls) << " failed, " << run.held
              << " held in a job on the stopped replica; jobs per replica "
              << "at the stop " << Describe(run.at_stop) << ", after "
              << Describe(run.after) << ", at the end " << Describe(run.at_end)
              << "\n";
    for (const Load::Call& call : run.calls) {
      if (!call.status.ok()) std::cout << "  failed: " << call.status << "\n";
    }
    return run;
  }

  // Starts Segment calls through the balanced client one at a time until
  // one holds at a stage boundary of replica `index` (whose stages must be
  // holding); returns that call, or null after 3 * kReplicas calls.
  std::unique_ptr<StreamCall> SegmentOnReplica(
      const fovea::v1::SegmentRequest& request, int index) {
    Checkpoint& stages = replicas_[index].stages;
    for (int i = 0; i < 3 * kReplicas; ++i) {
      const int held = stages.held();
      auto call = std::make_unique<StreamCall>(*client_, request);
      EXPECT_TRUE(
          WaitFor([&] { return call->done() || stages.held() > held; }, kWait));
      if (stages.held() > held) return call;
      EXPECT_TRUE(call->status().ok()) << call->status();
    }
    return nullptr;
  }

  // Segment at most one object of the test frame.
  fovea::v1::SegmentRequest SegmentRequest() const {
    fovea::v1::SegmentRequest request;
    *request.mutable_frame() = request_.frame();
    request.set_max_objects(1);
    return request;
  }

  std::array<Replica, kReplicas> replicas_;
  std::unique_ptr<FoveaClient> client_;
  fovea::v1::DetectRequest request_;
};

TEST_F(RoundRobinTest, EveryReplicaServesAndAStoppedOneLosesNoCall) {
  const StopRun run = StopOneMidRun(ClientOptions().max_attempts);
  ASSERT_GE(run.held, 1);
  // Every call succeeded: the ones in flight on the stopped replica failed
  // there with UNAVAILABLE and were retried on another. Each held one ran
  // a job on both (so did any whose reply the stop cut off); no other call
  // ran two.
  for (const Load::Call& call : run.calls) {
    EXPECT_TRUE(call.status.ok()) << call.status;
  }
  const int extra_jobs = run.at_end[0] + run.at_end[1] + run.at_end[2] -
                         static_cast<int>(run.calls.size());
  EXPECT_GE(extra_jobs, run.held);
  EXPECT_LE(extra_jobs, kThreads);  // at most one call per thread in flight
  // After the stop the other two take every call.
  EXPECT_EQ(run.after[1], run.at_stop[1]);
  EXPECT_GT(run.after[0], run.at_stop[0]);
  EXPECT_GT(run.after[2], run.at_stop[2]);
}

// Without retries the calls in flight on the stopped replica are lost with
// UNAVAILABLE (the held ones at least, and any still being sent to it);
// none that started after the stop is.
TEST_F(RoundRobinTest, WithoutRetriesOnlyCallsInFlightAtTheStopFail) {
  const StopRun run = StopOneMidRun(/*max_attempts=*/1);
  ASSERT_GE(run.held, 1);
  int failed = 0;
  for (const Load::Call& call : run.calls) {
    if (call.status.ok()) continue;
    ++failed;
    EXPECT_EQ(call.status.code(), absl::StatusCode::kUnavailable)
        << call.status;
    EXPECT_EQ(call.started, 0) << "started after the stop: " << call.status;
    EXPECT_GE(call.ended, 1) << "ended before the stop: " << call.status;
  }
  EXPECT_GE(failed, run.held);
  EXPECT_LE(failed, kThreads);  // at most one call per thread in flight
  EXPECT_EQ(run.after[1], run.at_stop[1]);
}

TEST_F(RoundRobinTest, DrainingReplicaGetsNoNewCalls) {
  Replica& draining = replicas_[1];
  ASSERT_TRUE(WaitFor(
      [&] {
        EXPECT_TRUE(Detect().ok());
        return draining.jobs.passed() > 0;
      },
      kWait));

  draining.server->Drain();
  // Once its health watch has said NOT_SERVING, two full rounds go by
  // without it.
  int since_last_job = 0;
  int seen = draining.jobs.passed();
  ASSERT_TRUE(WaitFor(
      [&] {
        EXPECT_TRUE(Detect().ok());
        const int now = draining.jobs.passed();
        since_last_job = now == seen ? since_last_job + 1 : 0;
        seen = now;
        return since_last_job >= 2 * kReplicas;
      },
      kWait))
      << "the draining replica still gets calls; jobs " << Describe(Jobs());

  const std::array<int, kReplicas> before = Jobs();
  for (int i = 0; i < 3 * kReplicas; ++i) {
    const absl::Status status = Detect();
    EXPECT_TRUE(status.ok()) << status;
  }
  const std::array<int, kReplicas> after = Jobs();
  std::cout << "jobs per replica after the drain: " << Describe(before)
            << ", nine calls later: " << Describe(after) << "\n";
  EXPECT_EQ(after[1], before[1]);
  EXPECT_GT(after[0], before[0]);
  EXPECT_GT(after[2], before[2]);

  // It still serves a call sent to it alone, and says it is draining.
  std::shared_ptr<grpc::Channel> direct =
      grpc::CreateChannel(draining.address, grpc::InsecureChannelCredentials());
  EXPECT_EQ(HealthStatus(direct, "fovea.v1.Perception"), "NOT_SERVING");
  absl::StatusOr<std::unique_ptr<FoveaClient>> alone =
      FoveaClient::Connect(draining.address);
  ASSERT_TRUE(alone.ok());
  EXPECT_EQ((*alone)
                ->Health("fovea.v1.Perception", kCallDeadline)
                .value_or(grpc::health::v1::HealthCheckResponse::UNKNOWN),
            grpc::health::v1::HealthCheckResponse::NOT_SERVING);
  fovea::v1::Perception::Stub stub(direct);
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + kCallDeadline));
  fovea::v1::DetectResponse response;
  EXPECT_TRUE(stub.Detect(&context, request_, &response).ok());
  EXPECT_EQ(draining.jobs.passed(), after[1] + 1);
}

// gRPC commits a call once a reply arrives. A stream cut off before its
// first message is retried on another replica, and the caller sees each
// message once.
TEST_F(RoundRobinTest, SegmentStreamIsRetriedBeforeItsFirstMessage) {
  Replica& stopped = replicas_[1];
  stopped.stages.Hold();  // at the first stage boundary, before any message
  std::unique_ptr<StreamCall> call = SegmentOnReplica(SegmentRequest(), 1);
  ASSERT_NE(call, nullptr) << "no call reached replica 1";
  EXPECT_TRUE(call->messages().empty());
  std::thread stopper([&] { stopped.server->Shutdown(absl::ZeroDuration()); });
  const bool done = WaitFor([&] { return call->done(); }, kWait);
  stopped.stages.Release();
  stopper.join();
  ASSERT_TRUE(done);

  EXPECT_TRUE(call->status().ok()) << call->status();
  const std::vector<fovea::v1::SegmentResponse> messages = call->messages();
  EXPECT_EQ(PointsMessages(messages), 1);
  EXPECT_EQ(LastMessages(messages), 1);
  ASSERT_FALSE(messages.empty());
  EXPECT_TRUE(messages.back().last());
}

// A stream cut off after its first message is not retried (the caller
// would see messages twice): it fails with UNAVAILABLE after them.
TEST_F(RoundRobinTest, SegmentStreamIsNotRetriedAfterItsFirstMessage) {
  Replica& stopped = replicas_[1];
  // How many stage boundaries the stream passes on replica 1, and how many
  // had passed when its first message arrived.
  absl::StatusOr<std::unique_ptr<FoveaClient>> direct =
      FoveaClient::Connect(stopped.address);
  ASSERT_TRUE(direct.ok());
  const int before = stopped.stages.passed();
  int at_first_message = -1;
  ASSERT_TRUE((*direct)
                  ->Segment(SegmentRequest(), kCallDeadline,
                            [&](const fovea::v1::SegmentResponse&) {
                              if (at_first_message < 0) {
                                at_first_message =
                                    stopped.stages.passed() - before;
                              }
                            })
                  .ok());
  const int boundaries = stopped.stages.passed() - before;
  // The last boundary comes after the first message was sent.
  ASSERT_LT(at_first_message, boundaries);

  stopped.stages.HoldFrom(boundaries);
  std::unique_ptr<StreamCall> call = SegmentOnReplica(SegmentRequest(), 1);
  ASSERT_NE(call, nullptr) << "no call reached replica 1";
  const bool got_first =
      WaitFor([&] { return !call->messages().empty(); }, kWait);
  std::thread stopper([&] { stopped.server->Shutdown(absl::ZeroDuration()); });
  const bool done = WaitFor([&] { return call->done(); }, kWait);
  stopped.stages.Release();
  stopper.join();
  ASSERT_TRUE(got_first);
  ASSERT_TRUE(done);

  EXPECT_EQ(call->status().code(), absl::StatusCode::kUnavailable)
      << call->status();
  const std::vector<fovea::v1::SegmentResponse> messages = call->messages();
  EXPECT_EQ(PointsMessages(messages), 1);
  EXPECT_EQ(LastMessages(messages), 0);
}

}  // namespace
}  // namespace fovea::client
