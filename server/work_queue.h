#ifndef FOVEA_SERVER_WORK_QUEUE_H_
#define FOVEA_SERVER_WORK_QUEUE_H_

#include <deque>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/functional/any_invocable.h"
#include "core/base/mutex.h"
#include "core/base/parallel.h"

namespace fovea::server {

// A fixed pool of worker threads with a bounded queue: the server's limit
// on how many frames are computed at once. CPU work runs here, never on
// gRPC's callback threads.
//
// At most `workers` jobs run at once and at most `queue_capacity` more wait;
// TrySubmit refuses a job beyond that, so the caller can answer
// RESOURCE_EXHAUSTED at once instead of letting work pile up. Jobs run in
// submission order.
//
// A job that throws is logged as an error and its worker goes on with the
// next job: an exception never takes the process down. The queue cannot
// finish a call on a job's behalf, so a job that owns a call catches what
// it can itself and finishes the call (PerceptionService's Detect job
// answers INTERNAL); what still escapes is only logged.
class WorkQueue {
 public:
  // `workers` >= 1, `queue_capacity` >= 0 (checked: FOVEA_CHECK). Each
  // job runs in a ParallelScope of `pool` (not owned; may be null: one
  // thread per job) and `threads_per_job` threads.
  WorkQueue(int workers, int queue_capacity, ThreadPool* pool = nullptr,
            int threads_per_job = 1);
  // Stop().
  ~WorkQueue();

  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  // Queues `job` and returns true, or returns false (and drops `job`
  // unrun) when the pool is full or stopped.
  //
  // `abandoned`, when given, says the job is no longer wanted (its call
  // was finished by someone else: the client left or its deadline passed
  // while it waited). An abandoned job never runs, leaves the queue at the
  // next TrySubmit or when a worker reaches it, and never counts against
  // the capacity, so a sequential client whose calls time out in the queue
  // is not refused because of its own earlier calls. Called under the
  // queue's lock: must be cheap and must not call the queue.
  bool TrySubmit(absl::AnyInvocable<void() &&> job,
                 absl::AnyInvocable<bool() const> abandoned = nullptr);

  // Queues `job` whatever the queue holds (false only when stopped): for a
  // job whose caller was admitted already and holds at most one job at a
  // time (an open Track stream's next frame; streams are limited), so the
  // queue holds at most queue_capacity + that many.
  bool SubmitAdmitted(absl::AnyInvocable<void() &&> job);

  // Whether TrySubmit would refuse a job now (it may still, or may not,
  // a moment later): what a call checks before parsing its request, so that
  // a refusal costs next to nothing.
  bool Full() const;

  // Refuses new jobs, runs every job already accepted, joins the workers.
  // Idempotent and safe to call from several threads at once: every caller
  // returns once the workers are joined. Accepted jobs always run: each one
  // owns a call that must be finished. Not from a job (a worker cannot
  // join itself).
  void Stop();

  int workers() const { return static_cast<int>(threads_.size()); }
  int queue_capacity() const { return queue_capacity_; }
  // Jobs accepted and not yet started.
  int waiting() const;
  // Jobs running now.
  int running() const;

 private:
  struct Job {
    absl::AnyInvocable<void() &&> run;
    absl::AnyInvocable<bool() const> abandoned;  // may be null
  };
  void WorkerLoop();
  // Drops the abandoned jobs from jobs_.
  void DropAbandonedLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const int queue_capacity_;
  std::vector<std::thread> threads_;

  // Held by Stop while it joins `threads_`, so concurrent Stops neither
  // join a thread twice nor return before the workers are gone. Taken
  // before mu_, never while holding it.
  Mutex stop_mu_;

  mutable Mutex mu_;
  std::deque<Job> jobs_ ABSL_GUARDED_BY(mu_);
  int running_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace fovea::server

#endif  // FOVEA_SERVER_WORK_QUEUE_H_
