#ifndef FOVEA_CORE_BASE_PARALLEL_H_
#define FOVEA_CORE_BASE_PARALLEL_H_

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "core/base/mutex.h"

namespace fovea {

// Helper threads shared by every request of a process, so that a request
// may use more than one core without each one starting threads of its own:
// the threads busy at once are at most the requests' own threads plus
// helpers(). Stages split their work with ParallelFor (below); a request
// says how many threads it may use with a ParallelScope.
class ThreadPool {
 public:
  // Starts `helpers` threads (0: ParallelFor runs on the caller alone).
  explicit ThreadPool(int helpers);
  ~ThreadPool();  // waits for the running tasks, then joins
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int helpers() const { return static_cast<int>(threads_.size()); }

  // Runs fn(i) for every i in [0, n), each exactly once, on the calling
  // thread and on at most `max_helpers` others (fewer when they are busy
  // with other requests' work: the caller never waits for a helper to
  // become free), and returns when every call has returned. The first
  // exception a call throws is rethrown here once all have returned.
  //
  // Items may call ParallelFor again, on any thread: the inner call fans
  // out in the same scope. A thread whose items are done while others'
  // are still running helps with the same request's queued work (its own
  // inner calls, or the other branch's), never with another request's.
  void ParallelFor(int n, int max_helpers, const std::function<void(int)>& fn);

 private:
  struct Job;
  void Work();
  void RunShare(Job& job);
  // A queued ticket of the request `family`, removed from the queue; null
  // when there is none.
  std::shared_ptr<Job> TakeTicketOf(uint64_t family)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);

  Mutex mutex_;
  std::deque<std::shared_ptr<Job>> queue_ ABSL_GUARDED_BY(mutex_);
  bool stopping_ ABSL_GUARDED_BY(mutex_) = false;
  std::vector<std::thread> threads_;
};

// While it lives, ParallelFor on this thread splits its work over `threads`
// threads in all (this one and threads - 1 of `pool`'s helpers). Scopes
// nest: the innermost one counts. Without a scope, ParallelFor runs
// serially. The outermost scope with a pool starts a request: the work
// that ParallelFor hands out on its behalf, however nested, is its own.
class ParallelScope {
 public:
  ParallelScope(ThreadPool* pool, int threads);
  ~ParallelScope();
  ParallelScope(const ParallelScope&) = delete;
  ParallelScope& operator=(const ParallelScope&) = delete;

 private:
  ThreadPool* previous_pool_;
  int previous_threads_;
  uint64_t previous_family_;
};

// The threads ParallelFor may use on this thread now (1 without a scope).
int ParallelThreads();

// 0 on any thread but a pool's helpers, which are numbered from 1.
int ParallelThreadIndex();

// fn(i) for every i in [0, n) through the current scope's pool (see
// ParallelScope); serially, in order, without one. Work split this way
// must give the same result in any order: each i writes only its own part
// of the output.
void ParallelFor(int n, const std::function<void(int)>& fn);

// ParallelFor over [0, n) in about ParallelThreads() * 4 contiguous
// ranges: fn(begin, end) for each, for loops over rows or items whose
// bodies are too small to be a task each.
void ParallelForRanges(int n, const std::function<void(int, int)>& fn);

// Runs `first` and `second`, at once when the current scope allows (see
// ParallelFor; the caller may run either), in order otherwise, and returns
// when both have. For two independent stages of one request; each must
// write only its own results.
void ParallelInvoke(const std::function<void()>& first,
                    const std::function<void()>& second);

// Routes OpenCV's own parallel loops (filters, colour conversions,
// resizing) through ParallelFor, so that they follow the calling thread's
// ParallelScope too: serial without one, instead of OpenCV's pool of one
// thread per core. Call once, from main, before any other thread starts.
void UseParallelScopesInOpenCv();

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_PARALLEL_H_
