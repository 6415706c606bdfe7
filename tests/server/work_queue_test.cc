#include "server/work_queue.h"

#include <algorithm>
#include <atomic>
#include <chrono>

#include "absl/synchronization/mutex.h"
#include "absl/synchronization/notification.h"
#include "absl/time/time.h"
#include "gtest/gtest.h"

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
  absl::Notification release;
  std::atomic<int> ran{0};
  ASSERT_TRUE(queue.TrySubmit([&] {
    release.WaitForNotification();
    ran.fetch_add(1);
  }));
  ASSERT_TRUE(Eventually([&] { return queue.running() == 1; }));
  EXPECT_TRUE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  EXPECT_EQ(queue.waiting(), 1);
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(100); }));
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 2);
}

TEST(WorkQueueTest, ZeroQueueStillFeedsAnIdleWorker) {
  WorkQueue queue(1, 0);
  absl::Notification release;
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
  absl::Mutex mu;
  int now = 0;
  int most = 0;
  absl::Notification release;
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(queue.TrySubmit([&] {
      {
        absl::MutexLock lock(&mu);
        most = std::max(most, ++now);
      }
      release.WaitForNotification();
      absl::MutexLock lock(&mu);
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
  absl::Notification release;
  ASSERT_TRUE(queue.TrySubmit([&] {
    release.WaitForNotification();
    ran.fetch_add(1);
  }));
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  }
  release.Notify();
  queue.Stop();
  EXPECT_EQ(ran.load(), 6);
  EXPECT_FALSE(queue.TrySubmit([&] { ran.fetch_add(1); }));
  queue.Stop();  // idempotent
}

}  // namespace
}  // namespace fovea::server
