#include "core/base/parallel.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <opencv2/core.hpp>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace fovea {
namespace {

TEST(ParallelForTest, WithoutAScopeRunsInOrderOnTheCaller) {
  std::vector<int> order;
  const std::thread::id caller = std::this_thread::get_id();
  bool elsewhere = false;
  ParallelFor(5, [&](int i) {
    order.push_back(i);
    elsewhere |= std::this_thread::get_id() != caller;
  });
  EXPECT_THAT(order, testing::ElementsAre(0, 1, 2, 3, 4));
  EXPECT_FALSE(elsewhere);
  EXPECT_EQ(ParallelThreads(), 1);
}

TEST(ParallelForTest, EveryItemRunsExactlyOnceOnAtMostTheScopesThreads) {
  ThreadPool pool(3);
  ParallelScope scope(&pool, 2);  // the caller and one helper
  EXPECT_EQ(ParallelThreads(), 2);
  constexpr int kItems = 2000;
  std::vector<std::atomic<int>> runs(kItems);
  std::mutex mutex;
  std::set<std::thread::id> threads;
  ParallelFor(kItems, [&](int i) {
    runs[i].fetch_add(1);
    std::lock_guard<std::mutex> lock(mutex);
    threads.insert(std::this_thread::get_id());
  });
  for (int i = 0; i < kItems; ++i) ASSERT_EQ(runs[i].load(), 1) << i;
  EXPECT_LE(threads.size(), 2u);
}

TEST(ParallelForTest, RangesCoverTheIntervalWithoutOverlap) {
  ThreadPool pool(1);
  ParallelScope scope(&pool, 2);
  for (const int n : {1, 2, 7, 8, 9, 480}) {
    std::vector<int> hits(n, 0);
    std::mutex mutex;
    ParallelForRanges(n, [&](int begin, int end) {
      ASSERT_LT(begin, end);
      std::lock_guard<std::mutex> lock(mutex);
      for (int i = begin; i < end; ++i) ++hits[i];
    });
    EXPECT_THAT(hits, testing::Each(1)) << n;
  }
}

TEST(ParallelForTest, AnExceptionReachesTheCallerAfterEveryItemReturned) {
  ThreadPool pool(2);
  ParallelScope scope(&pool, 3);
  std::atomic<int> ran{0};
  EXPECT_THROW(ParallelFor(100,
                           [&](int i) {
                             ran.fetch_add(1);
                             if (i == 17) throw std::runtime_error("item 17");
                           }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 100);
}

TEST(ParallelForTest, NestedCallsFanOutOnAnyThreadAndFinish) {
  ThreadPool pool(1);
  ParallelScope scope(&pool, 2);
  std::atomic<int> inner{0};
  ParallelFor(8,
              [&](int) { ParallelFor(8, [&](int) { inner.fetch_add(1); }); });
  EXPECT_EQ(inner.load(), 64);
}

// Two branches of one request: the short one's thread, once done, helps
// the long one's inner loop, which would otherwise run on one thread.
TEST(ParallelForTest, AThreadThatIsDoneHelpsItsRequestsOtherBranch) {
  ThreadPool pool(1);
  ParallelScope scope(&pool, 2);
  std::mutex mutex;
  std::set<std::thread::id> inner_threads;
  ParallelInvoke([] {},
                 [&] {
                   ParallelFor(64, [&](int) {
                     std::this_thread::sleep_for(std::chrono::milliseconds(2));
                     std::lock_guard<std::mutex> lock(mutex);
                     inner_threads.insert(std::this_thread::get_id());
                   });
                 });
  EXPECT_EQ(inner_threads.size(), 2u);
}

// A request's waiting thread helps only its own request: with one helper
// busy elsewhere, request B's items all run on B's own thread, never on
// request A's, which is waiting for its slow item.
TEST(ParallelForTest, AWaitingThreadNeverRunsAnotherRequestsWork) {
  ThreadPool pool(1);
  std::atomic<bool> a_waiting{false};
  std::atomic<bool> b_done{false};
  std::thread::id a_thread;
  std::mutex mutex;
  std::set<std::thread::id> b_threads;
  std::thread a([&] {
    a_thread = std::this_thread::get_id();
    ParallelScope scope(&pool, 2);
    std::atomic<bool> second_started{false};
    // Roles by thread, not by item: either item may be the one A's own
    // thread takes (the pool's worker may take item 0 first).
    ParallelFor(2, [&](int) {
      const auto until =
          std::chrono::steady_clock::now() + std::chrono::seconds(10);
      if (std::this_thread::get_id() == a_thread) {
        // Until the other item runs on the other thread; then A's thread
        // has nothing of its own to do and waits.
        while (!second_started.load() &&
               std::chrono::steady_clock::now() < until) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        a_waiting.store(true);
        return;
      }
      // The helper, busy until B has finished.
      second_started.store(true);
      while (!b_done.load() && std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
  });
  while (!a_waiting.load()) std::this_thread::yield();
  {
    ParallelScope scope(&pool, 2);
    ParallelFor(32, [&](int) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      std::lock_guard<std::mutex> lock(mutex);
      b_threads.insert(std::this_thread::get_id());
    });
  }
  b_done.store(true);
  a.join();
  EXPECT_EQ(b_threads.count(a_thread), 0u);
  EXPECT_EQ(b_threads.size(), 1u);
}

TEST(ParallelForTest, ConcurrentRequestsShareOnePoolAndAllFinish) {
  ThreadPool pool(1);
  std::vector<std::thread> requests;
  std::atomic<long> sum{0};
  for (int r = 0; r < 4; ++r) {
    requests.emplace_back([&] {
      ParallelScope scope(&pool, 2);
      for (int k = 0; k < 50; ++k) {
        ParallelFor(64, [&](int i) { sum.fetch_add(i); });
      }
    });
  }
  for (std::thread& t : requests) t.join();
  EXPECT_EQ(sum.load(), 4L * 50 * (63 * 64 / 2));
}

TEST(ParallelInvokeTest, WithoutAScopeRunsBothInOrder) {
  std::vector<int> order;
  ParallelInvoke([&] { order.push_back(1); }, [&] { order.push_back(2); });
  EXPECT_THAT(order, testing::ElementsAre(1, 2));
}

TEST(ParallelInvokeTest, WithAFreeHelperBothRunAtOnce) {
  ThreadPool pool(1);
  ParallelScope scope(&pool, 2);
  // Whichever thread runs `first` waits for `second` to start: in order,
  // it would wait its whole 10 s and see it had not.
  std::atomic<bool> second_started{false};
  std::atomic<int> runs{0};
  bool overlapped = false;
  ParallelInvoke(
      [&] {
        const auto until =
            std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (!second_started.load() &&
               std::chrono::steady_clock::now() < until) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        overlapped = second_started.load();
        runs.fetch_add(1);
      },
      [&] {
        second_started.store(true);
        runs.fetch_add(1);
      });
  EXPECT_TRUE(overlapped);
  EXPECT_EQ(runs.load(), 2);
}

TEST(ParallelScopeTest, ScopesNestAndRestore) {
  ThreadPool pool(1);
  {
    ParallelScope outer(&pool, 2);
    {
      ParallelScope inner(&pool, 1);
      EXPECT_EQ(ParallelThreads(), 1);
    }
    EXPECT_EQ(ParallelThreads(), 2);
  }
  EXPECT_EQ(ParallelThreads(), 1);
  ParallelScope none(nullptr, 4);
  EXPECT_EQ(ParallelThreads(), 1);
}

TEST(UseParallelScopesInOpenCvTest, OpenCvLoopsFollowTheScope) {
  UseParallelScopesInOpenCv();
  const auto threads_used = [] {
    std::mutex mutex;
    std::set<std::thread::id> threads;
    cv::parallel_for_(cv::Range(0, 64), [&](const cv::Range& range) {
      // Long enough that both threads get some of the stripes.
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      std::lock_guard<std::mutex> lock(mutex);
      for (int i = range.start; i < range.end; ++i) {
        threads.insert(std::this_thread::get_id());
      }
    });
    return threads.size();
  };
  EXPECT_EQ(threads_used(), 1u);  // no scope: the caller alone
  EXPECT_EQ(cv::getNumThreads(), 1);
  ThreadPool pool(1);
  ParallelScope scope(&pool, 2);
  EXPECT_EQ(cv::getNumThreads(), 2);
  EXPECT_EQ(threads_used(), 2u);
}

}  // namespace
}  // namespace fovea
