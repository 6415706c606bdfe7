#include "server/work_queue.h"

#include <exception>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "server/log.h"

namespace fovea::server {
namespace {

// Runs `job`; logs and swallows anything it throws, so the worker lives on.
void RunGuarded(absl::AnyInvocable<void() &&> job) {
  try {
    std::move(job)();
  } catch (const std::exception& e) {
    LogError(
        absl::StrCat("work queue: a job threw (worker goes on): ", e.what()));
  } catch (...) {
    LogError(
        "work queue: a job threw a non-standard exception (worker goes "
        "on)");
  }
}

}  // namespace

WorkQueue::WorkQueue(int workers, int queue_capacity, ThreadPool* pool,
                     int threads_per_job)
    : queue_capacity_(queue_capacity) {
  FOVEA_CHECK(workers >= 1);
  FOVEA_CHECK(queue_capacity >= 0);
  FOVEA_CHECK(threads_per_job >= 1);
  threads_.reserve(workers);
  for (int i = 0; i < workers; ++i) {
    threads_.emplace_back([this, pool, threads_per_job] {
      const ParallelScope scope(pool, threads_per_job);
      WorkerLoop();
    });
  }
}

WorkQueue::~WorkQueue() { Stop(); }

bool WorkQueue::TrySubmit(absl::AnyInvocable<void() &&> job,
                          absl::AnyInvocable<bool() const> abandoned) {
  MutexLock lock(&mu_);
  if (stopping_) return false;
  DropAbandonedLocked();
  // A job counts against the queue only if no worker is free to take it.
  const int in_system = running_ + static_cast<int>(jobs_.size());
  if (in_system >= workers() + queue_capacity_) return false;
  jobs_.push_back({std::move(job), std::move(abandoned)});
  return true;
}

bool WorkQueue::SubmitAdmitted(absl::AnyInvocable<void() &&> job) {
  MutexLock lock(&mu_);
  if (stopping_) return false;
  jobs_.push_back({std::move(job), nullptr});
  return true;
}

bool WorkQueue::Full() const {
  MutexLock lock(&mu_);
  int in_system = running_;
  for (const Job& job : jobs_) {
    in_system += !(job.abandoned && job.abandoned());
  }
  return stopping_ || in_system >= workers() + queue_capacity_;
}

void WorkQueue::DropAbandonedLocked() {
  for (auto it = jobs_.begin(); it != jobs_.end();) {
    if (it->abandoned && it->abandoned()) {
      it = jobs_.erase(it);
    } else {
      ++it;
    }
  }
}

void WorkQueue::Stop() {
  MutexLock stop_lock(&stop_mu_);
  {
    MutexLock lock(&mu_);
    stopping_ = true;
  }
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

int WorkQueue::waiting() const {
  MutexLock lock(&mu_);
  int waiting = 0;
  for (const Job& job : jobs_) {
    waiting += job.abandoned && job.abandoned() ? 0 : 1;
  }
  return waiting;
}

int WorkQueue::running() const {
  MutexLock lock(&mu_);
  return running_;
}

void WorkQueue::WorkerLoop() {
  while (true) {
    absl::AnyInvocable<void() &&> job;
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        return !jobs_.empty() || stopping_;
      });
      if (jobs_.empty()) return;  // stopping and drained
      Job next = std::move(jobs_.front());
      jobs_.pop_front();
      if (next.abandoned && next.abandoned()) continue;
      job = std::move(next.run);
      ++running_;
    }
    RunGuarded(std::move(job));
    MutexLock lock(&mu_);
    --running_;
  }
}

}  // namespace fovea::server
