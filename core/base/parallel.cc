#include "core/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <utility>

namespace fovea {

namespace {

thread_local ThreadPool* current_pool = nullptr;
thread_local int current_threads = 1;
// 0 on a request's thread, 1.. on a pool's helpers.
thread_local int thread_index = 0;
// The request the work on this thread is for (0: none yet): the outermost
// ParallelScope with a pool starts one; a helper takes its job's.
thread_local uint64_t current_family = 0;
std::atomic<uint64_t> next_family{1};

// Sets this thread's scope and family for the life of the object.
class ScopeAs {
 public:
  ScopeAs(ThreadPool* pool, int threads, uint64_t family)
      : pool_(current_pool),
        threads_(current_threads),
        family_(current_family) {
    current_pool = pool;
    current_threads = threads;
    current_family = family;
  }
  ~ScopeAs() {
    current_pool = pool_;
    current_threads = threads_;
    current_family = family_;
  }

 private:
  ThreadPool* pool_;
  int threads_;
  uint64_t family_;
};

}  // namespace

// One ParallelFor call: its items are taken by index by whoever runs it
// (the caller and the threads that picked up one of its tickets).
struct ThreadPool::Job {
  const std::function<void(int)>* fn = nullptr;
  int n = 0;
  int threads = 1;      // the scope its items run in
  uint64_t family = 0;  // the request it is for
  std::atomic<int> next{0};
  // Guarded by the pool's mutex_ (one lock for every job: what a waiting
  // thread waits for is "my job is done, or there is work of my request").
  int finished = 0;
  std::exception_ptr error;
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
  MutexLock lock(&mutex_);
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
    // In the job's scope: a ParallelFor inside an item fans out too.
    const ScopeAs scope(this, job->threads, job->family);
    RunShare(*job);
  }
}

std::shared_ptr<ThreadPool::Job> ThreadPool::TakeTicketOf(uint64_t family) {
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if ((*it)->family == family) {
      std::shared_ptr<Job> job = std::move(*it);
      queue_.erase(it);
      return job;
    }
  }
  return nullptr;
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
  job->threads = current_threads;
  job->family = current_family;
  {
    MutexLock lock(&mutex_);
    for (int t = 0; t < tickets; ++t) queue_.push_back(job);
  }
  RunShare(*job);
  // Until every item has returned, help with this request's other work
  // (the tickets of the jobs its other threads started) rather than wait
  // idle; a ticket taken after the job is done finds no item left
  // (next >= n) and never touches `fn`.
  const uint64_t family = job->family;
  mutex_.Lock();
  while (job->finished < job->n) {
    std::shared_ptr<Job> other = TakeTicketOf(family);
    if (other != nullptr) {
      mutex_.Unlock();
      RunShare(*other);
      mutex_.Lock();
      continue;
    }
    mutex_.Await([&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) {
      if (job->finished == job->n) return true;
      for (const std::shared_ptr<Job>& queued : queue_) {
        if (queued->family == family) return true;
      }
      return false;
    });
  }
  const std::exception_ptr error = job->error;
  mutex_.Unlock();
  if (error) std::rethrow_exception(error);
}

ParallelScope::ParallelScope(ThreadPool* pool, int threads)
    : previous_pool_(current_pool),
      previous_threads_(current_threads),
      previous_family_(current_family) {
  current_pool = pool;
  current_threads = pool == nullptr ? 1 : std::max(1, threads);
  if (pool != nullptr && current_family == 0) {
    current_family = next_family.fetch_add(1);
  }
}

ParallelScope::~ParallelScope() {
  current_pool = previous_pool_;
  current_threads = previous_threads_;
  current_family = previous_family_;
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
