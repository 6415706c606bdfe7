#include "server/work_queue.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "core/base/mutex.h"
#include "core/base/parallel.h"
#include "gtest/gtest.h"
#include "server/server.h"

namespace fovea::server {
namespace {

constexpr absl::Duration kTimeout = absl::Seconds(30);

// Waits (bounded) until `condition` holds on `queue`.
template <typename Condition>
bool Eventually(Condition condition) {
  const absl::Time end = absl::Now() + kTimeout;
  while (!condition()) {
    if (absl::Now() > end) return false;
    absl::SleepFor(absl::Milliseconds(1));
  }
  return true;
}

// Submits a job that waits for `release`, then counts itself in `ran`,
// and waits until a worker runs it. False when refused or never started.
bool SubmitHeldJob(WorkQueue& queue, Notification& release,
                   std::atomic<int>& ran) {
  const int running = queue.running();
  return queue.TrySubmit([&release, &ran] {
    release.WaitForNotification();
    ran.fetch_add(1);
  }) && Eventually([&] { return queue.running() == running + 1; });
}

TEST(WorkQueueTest, RunsEveryAcceptedJob) {
  std::atomic<int> ran{0};
  {
    WorkQueue queue(2, 10);
    for (int i = 0; i < 12; ++i) {
      EXPECT_TRUE(queue.TrySubmit([&ran] { ran.fetch_add(1); }));
    }
    queue.Stop();
  }
  EXPECT_EQ(ran.load(), 12);
}

TEST(WorkQueueTest, RefusesBeyondWorkersPlusQueue) {
  WorkQueue queue(1, 1);
  Notification release;
  std::atomic<int> ran{0};
  ASSERT_TRUE(SubmitHeldJob(queue, release, ran));
  EXPECT_TRUE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  EXPECT_EQ(queue.waiting(), 1);
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(100); }));
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 2);
}

// An admitted caller's job is queued past the capacity; Full says what
// TrySubmit would do, abandoned jobs not counted.
TEST(WorkQueueTest, AdmittedJobsQueuePastTheCapacityAndFullSaysSo) {
  WorkQueue queue(1, 1);
  Notification release;
  std::atomic<int> ran{0};
  EXPECT_FALSE(queue.Full());
  ASSERT_TRUE(SubmitHeldJob(queue, release, ran));
  EXPECT_FALSE(queue.Full());  // one queue slot left
  std::atomic<bool> gone{false};
  EXPECT_TRUE(queue.TrySubmit([&] { ran.fetch_add(100); },
                              [&] { return gone.load(); }));
  EXPECT_TRUE(queue.Full());
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(1000); }));
  gone = true;  // the abandoned one no longer counts
  EXPECT_FALSE(queue.Full());
  EXPECT_TRUE(queue.SubmitAdmitted([&] { ran.fetch_add(1); }));
  EXPECT_TRUE(queue.Full());
  EXPECT_TRUE(queue.SubmitAdmitted([&] { ran.fetch_add(1); }));  // past it
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 3);   // the held job and the two admitted ones
  EXPECT_TRUE(queue.Full());  // stopped: nothing more is taken
  EXPECT_FALSE(queue.SubmitAdmitted([&] { ran.fetch_add(1); }));
}

TEST(WorkQueueTest, AbandonedJobsNeverRunAndFreeTheirSlot) {
  WorkQueue queue(1, 1);
  Notification release;
  std::atomic<int> ran{0};
  std::atomic<bool> gone{false};
  ASSERT_TRUE(SubmitHeldJob(queue, release, ran));
  EXPECT_TRUE(queue.TrySubmit([&] { ran.fetch_add(100); },
                              [&] { return gone.load(); }));
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(1000); }));  // full
  gone = true;  // its caller left: the slot is free again
  EXPECT_EQ(queue.waiting(), 0);
  EXPECT_TRUE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 2);  // the held job and the last one
}

TEST(WorkQueueTest, ZeroQueueStillFeedsAnIdleWorker) {
  WorkQueue queue(1, 0);
  Notification release;
  ASSERT_TRUE(queue.TrySubmit([&] { release.WaitForNotification(); }));
  ASSERT_TRUE(Eventually([&] { return queue.running() == 1; }));
  EXPECT_FALSE(queue.TrySubmit([] {}));
  release.Notify();
  ASSERT_TRUE(Eventually([&] { return queue.running() == 0; }));
  EXPECT_TRUE(queue.TrySubmit([] {}));
}

TEST(WorkQueueTest, NeverRunsMoreThanWorkersAtOnce) {
  constexpr int kWorkers = 2;
  WorkQueue queue(kWorkers, 100);
  Mutex mu;
  int now = 0;
  int most = 0;
  Notification release;
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(queue.TrySubmit([&] {
      {
        MutexLock lock(&mu);
        most = std::max(most, ++now);
      }
      release.WaitForNotification();
      MutexLock lock(&mu);
      --now;
    }));
  }
  // Both workers are held and the other 18 jobs wait.
  ASSERT_TRUE(Eventually([&] { return queue.running() == kWorkers; }));
  EXPECT_EQ(queue.waiting(), 20 - kWorkers);
  release.Notify();
  queue.Stop();
  EXPECT_EQ(most, kWorkers);
}

TEST(WorkQueueTest, StopRunsQueuedJobsAndRefusesNewOnes) {
  std::atomic<int> ran{0};
  WorkQueue queue(1, 5);
  Notification release;
  ASSERT_TRUE(SubmitHeldJob(queue, release, ran));
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  }
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 6);
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  queue.Stop();  // idempotent
}

TEST(WorkQueueTest, JobThatThrowsDoesNotStopItsWorker) {
  std::atomic<int> ran{0};
  WorkQueue queue(1, 5);
  ASSERT_TRUE(queue.TrySubmit([] { throw std::runtime_error("job failed"); }));
  ASSERT_TRUE(queue.TrySubmit([] { throw 42; }));
  ASSERT_TRUE(queue.TrySubmit([&ran] { ran.fetch_add(1); }));
  // The only worker survived both throws and ran the third job.
  ASSERT_TRUE(Eventually([&] { return ran.load() == 1; }));
  EXPECT_EQ(queue.running(), 0);
  EXPECT_TRUE(queue.TrySubmit([&ran] { ran.fetch_add(1); }));
  queue.Stop();
  EXPECT_EQ(ran.load(), 2);
}

TEST(WorkQueueTest, ConcurrentStopsJoinOnceAndReturnAfterTheJobs) {
  constexpr int kStoppers = 4;
  WorkQueue queue(2, 2);
  Notification release;
  std::atomic<int> ran{0};
  ASSERT_TRUE(SubmitHeldJob(queue, release, ran));
  // Every stopper reaches the joins while the job is held.
  std::vector<int> ran_when_stopped(kStoppers, -1);
  std::atomic<int> stopped{0};
  std::vector<std::thread> stoppers;
  for (int i = 0; i < kStoppers; ++i) {
    stoppers.emplace_back([&, i] {
      queue.Stop();
      ran_when_stopped[i] = ran.load();
      stopped.fetch_add(1);
    });
  }
  absl::SleepFor(absl::Milliseconds(100));
  release.Notify();
  if (!Eventually([&] { return stopped.load() == kStoppers; })) {
    // Two threads joining one worker can block for ever: fail now rather
    // than hang (the stuck threads cannot be joined or destroyed).
    ADD_FAILURE() << "a concurrent Stop never returned";
    std::fflush(nullptr);
    std::_Exit(1);
  }
  for (std::thread& stopper : stoppers) stopper.join();
  // No Stop returned before the accepted job had run.
  for (int i = 0; i < kStoppers; ++i) EXPECT_EQ(ran_when_stopped[i], 1) << i;
  EXPECT_FALSE(queue.TrySubmit([] {}));
}

TEST(WorkQueueTest, JobsRunInTheirWorkersParallelScope) {
  ThreadPool pool(1);
  WorkQueue queue(2, 2, &pool, 2);
  std::atomic<int> threads{0};
  std::atomic<int> items{0};
  Notification done;
  ASSERT_TRUE(queue.TrySubmit([&] {
    threads.store(ParallelThreads());
    ParallelFor(100, [&](int) { items.fetch_add(1); });
    done.Notify();
  }));
  done.WaitForNotification();
  EXPECT_EQ(threads.load(), 2);
  EXPECT_EQ(items.load(), 100);
}

TEST(WorkQueueTest, WithoutAPoolJobsRunOnOneThread) {
  WorkQueue queue(1, 1);
  std::atomic<int> threads{0};
  Notification done;
  ASSERT_TRUE(queue.TrySubmit([&] {
    threads.store(ParallelThreads());
    done.Notify();
  }));
  done.WaitForNotification();
  EXPECT_EQ(threads.load(), 1);
}

// The threads computing at once (workers + helpers) never outnumber the
// cores, whatever threads_per_request asks for.
TEST(EffectiveThreadsTest, DefaultSplitsTheCoresAndNothingOversubscribes) {
  struct Case {
    int cores, concurrency, asked, threads, helpers;
  };
  for (const Case& c : {
           Case{2, 2, 0, 1, 0},  // the default deployment: a core per frame
           Case{2, 1, 0, 2, 1},  // one worker gets both cores
           Case{8, 2, 0, 4, 6},
           Case{2, 1, 4, 2, 1},  // asked for more than the cores
           Case{2, 2, 2, 1, 0},  // no core left for helpers
           Case{4, 2, 3, 3,
                2},  // 2 helpers shared: 3 threads when the other worker idles
           Case{1, 4, 0, 1, 0},  // more workers than cores
       }) {
    ServerConfig config;
    config.cores = c.cores;
    config.concurrency = c.concurrency;
    config.threads_per_request = c.asked;
    const ThreadBudget budget = EffectiveThreads(config);
    EXPECT_EQ(budget.threads_per_request, c.threads)
        << c.cores << " cores, concurrency " << c.concurrency << ", asked "
        << c.asked;
    EXPECT_EQ(budget.helpers, c.helpers)
        << c.cores << " cores, concurrency " << c.concurrency;
    EXPECT_LE(c.concurrency + budget.helpers, std::max(c.cores, c.concurrency));
  }
}

TEST(EffectiveThreadsTest, NegativeThreadsPerRequestIsRefusedNamingTheFlag) {
  ServerConfig config;
  config.threads_per_request = -1;
  const absl::Status status = Validate(config);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("--threads_per_request"),
            absl::string_view::npos)
      << status;
}

}  // namespace
}  // namespace fovea::server
