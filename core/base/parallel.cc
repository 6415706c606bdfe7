#include "core/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <utility>

namespace fovea {

namespace {

thread_local ThreadPool* current_pool = nullptr;
thread_local int current_threads = 1;
// 0 on a request's thread, 1.. on a pool's helpers.
thread_local int thread_index = 0;

}  // namespace

// One ParallelFor call: its items are taken by index by whoever runs it
// (the caller and the helpers that picked up one of its tickets).
struct ThreadPool::Job {
  const std::function<void(int)>* fn = nullptr;
  int n = 0;
  std::atomic<int> next{0};
  Mutex mutex;
  int finished ABSL_GUARDED_BY(mutex) = 0;
  std::exception_ptr error ABSL_GUARDED_BY(mutex);
};

ThreadPool::ThreadPool(int helpers) {
  for (int i = 0; i < helpers; ++i) {
    threads_.emplace_back([this, i] {
      thread_index = i + 1;
      Work();
    });
  }
}

ThreadPool::~ThreadPool() {
  {
    MutexLock lock(&mutex_);
    stopping_ = true;
  }
  for (std::thread& t : threads_) t.join();
}

void ThreadPool::RunShare(Job& job) {
  int done = 0;
  std::exception_ptr error;
  for (int i = job.next.fetch_add(1); i < job.n; i = job.next.fetch_add(1)) {
    try {
      (*job.fn)(i);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
    ++done;
  }
  if (done == 0) return;
  MutexLock lock(&job.mutex);
  job.finished += done;
  if (error && !job.error) job.error = error;
}

void ThreadPool::Work() {
  while (true) {
    std::shared_ptr<Job> job;
    {
      MutexLock lock(&mutex_);
      mutex_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) {
        return stopping_ || !queue_.empty();
      });
      if (queue_.empty()) return;  // stopping, nothing left
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    // A helper runs what it takes serially: no nested fan-out.
    RunShare(*job);
  }
}

void ThreadPool::ParallelFor(int n, int max_helpers,
                             const std::function<void(int)>& fn) {
  if (n <= 0) return;
  const int tickets = std::min({max_helpers, helpers(), n - 1});
  if (tickets <= 0) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  auto job = std::make_shared<Job>();
  job->fn = &fn;
  job->n = n;
  {
    MutexLock lock(&mutex_);
    for (int t = 0; t < tickets; ++t) queue_.push_back(job);
  }
  RunShare(*job);
  MutexLock lock(&job->mutex);
  // A ticket a helper takes after this returns finds no item left
  // (next >= n) and never touches `fn`.
  job->mutex.Await([&job]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(job->mutex) {
    return job->finished == job->n;
  });
  if (job->error) std::rethrow_exception(job->error);
}

ParallelScope::ParallelScope(ThreadPool* pool, int threads)
    : previous_pool_(current_pool), previous_threads_(current_threads) {
  current_pool = pool;
  current_threads = pool == nullptr ? 1 : std::max(1, threads);
}

ParallelScope::~ParallelScope() {
  current_pool = previous_pool_;
  current_threads = previous_threads_;
}

int ParallelThreads() { return current_threads; }

int ParallelThreadIndex() { return thread_index; }

void ParallelFor(int n, const std::function<void(int)>& fn) {
  ThreadPool* pool = current_pool;
  const int threads = current_threads;
  if (pool == nullptr || threads <= 1) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  pool->ParallelFor(n, threads - 1, fn);
}

void ParallelInvoke(const std::function<void()>& first,
                    const std::function<void()>& second) {
  ParallelFor(2, [&](int i) { i == 0 ? first() : second(); });
}

void ParallelForRanges(int n, const std::function<void(int, int)>& fn) {
  if (n <= 0) return;
  const int threads = ParallelThreads();
  if (threads <= 1) {
    fn(0, n);
    return;
  }
  const int ranges = std::min(n, threads * 4);
  ParallelFor(ranges, [&](int r) {
    const int begin = static_cast<int>(static_cast<long long>(n) * r / ranges);
    const int end =
        static_cast<int>(static_cast<long long>(n) * (r + 1) / ranges);
    if (begin < end) fn(begin, end);
  });
}

}  // namespace fovea
