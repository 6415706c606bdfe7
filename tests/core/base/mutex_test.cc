#include "core/base/mutex.h"

#include <thread>
#include <vector>

#include "absl/time/time.h"
#include "gtest/gtest.h"

namespace fovea {
namespace {

// Threads increment one counter under the lock; none is lost. Under
// ThreadSanitizer (scripts/test --sanitize thread) a lock it cannot see
// would make this a reported race, which is what Mutex exists to avoid.
TEST(MutexTest, IncrementsUnderTheLockAreNotLost) {
  Mutex mu;
  int count = 0;
  constexpr int kThreads = 4;
  constexpr int kIncrements = 10000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < kIncrements; ++i) {
        MutexLock lock(&mu);
        ++count;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  MutexLock lock(&mu);
  EXPECT_EQ(count, kThreads * kIncrements);
}

// Await returns once another thread makes the predicate true, with no
// signal but the unlock: a relay of three waiters, each waiting for the
// previous one's step.
TEST(MutexTest, AwaitWakesWhenAnotherThreadChangesTheState) {
  Mutex mu;
  int step = 0;
  std::vector<std::thread> threads;
  for (int t = 1; t <= 3; ++t) {
    threads.emplace_back([&, t] {
      MutexLock lock(&mu);
      mu.Await([&]() { return step == t - 1; });
      step = t;
    });
  }
  {
    MutexLock lock(&mu);
    mu.Await([&]() { return step == 3; });
    EXPECT_EQ(step, 3);
  }
  for (std::thread& thread : threads) thread.join();
}

TEST(MutexTest, AwaitWithTimeoutGivesUpAndReportsThePredicate) {
  Mutex mu;
  MutexLock lock(&mu);
  EXPECT_FALSE(
      mu.AwaitWithTimeout([] { return false; }, absl::Milliseconds(5)));
  EXPECT_TRUE(mu.AwaitWithTimeout([] { return true; }, absl::Hours(1)));
  EXPECT_TRUE(
      mu.AwaitWithTimeout([] { return true; }, absl::InfiniteDuration()));
}

TEST(NotificationTest, WaitReturnsAfterNotifyFromAnotherThread) {
  Notification done;
  int value = 0;
  std::thread writer([&] {
    value = 42;  // published by Notify, read after the wait
    done.Notify();
  });
  done.WaitForNotification();
  EXPECT_TRUE(done.HasBeenNotified());
  EXPECT_EQ(value, 42);
  writer.join();
}

TEST(NotificationTest, TimedWaitWithoutNotifyTimesOut) {
  Notification never;
  EXPECT_FALSE(never.WaitForNotificationWithTimeout(absl::Milliseconds(5)));
  EXPECT_FALSE(never.HasBeenNotified());
  never.Notify();
  EXPECT_TRUE(never.WaitForNotificationWithTimeout(absl::Milliseconds(5)));
}

// The waiter destroys the notification as soon as its wait returns, while
// the notifying thread may still be inside Notify: Notify must not touch
// the object after the waiter can see it notified. (AddressSanitizer
// reports a use after free if it does.)
TEST(NotificationTest, WaiterMayDestroyItRightAfterTheWait) {
  for (int round = 0; round < 200; ++round) {
    auto* note = new Notification;
    std::thread notifier([note] { note->Notify(); });
    note->WaitForNotification();
    delete note;
    notifier.join();
  }
}

}  // namespace
}  // namespace fovea
