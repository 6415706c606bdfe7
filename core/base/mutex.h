#ifndef FOVEA_CORE_BASE_MUTEX_H_
#define FOVEA_CORE_BASE_MUTEX_H_

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/time/time.h"

namespace fovea {

// A mutex with absl::Mutex's shape (Lock, Unlock, Await on a predicate,
// thread-safety annotations), built on std::mutex and
// std::condition_variable.
//
// Why not absl::Mutex: Debian's abseil is not built with ThreadSanitizer,
// so absl::Mutex's locking is invisible to it and every access it guards
// is reported as a race. std::mutex is a pthread mutex, which TSan
// intercepts, so `scripts/test --sanitize thread` checks our own locking.
// Use this (and Notification below) for all locking in fovea's code.
//
// Await needs no explicit signal: Unlock wakes the waiters, which
// re-evaluate their predicates under the lock, as absl::Mutex does.
class ABSL_LOCKABLE Mutex {
 public:
  Mutex() = default;
  Mutex(const Mutex&) = delete;
  Mutex& operator=(const Mutex&) = delete;

  void Lock() ABSL_EXCLUSIVE_LOCK_FUNCTION() { mutex_.lock(); }

  // Wakes the waiters before releasing the lock: once it is released, a
  // waiter may return and destroy this mutex (a Notification on its stack).
  void Unlock() ABSL_UNLOCK_FUNCTION() {
    if (waiters_ > 0) changed_.notify_all();
    mutex_.unlock();
  }

  // Blocks until `done()` is true; `done` is evaluated with the lock held,
  // which is released while waiting. Requires the lock.
  template <typename Predicate>
  void Await(Predicate done) ABSL_EXCLUSIVE_LOCKS_REQUIRED(this) {
    std::unique_lock<std::mutex> lock(mutex_, std::adopt_lock);
    ++waiters_;
    changed_.wait(lock, std::move(done));
    --waiters_;
    lock.release();
  }

  // Await for at most `timeout` (absl::InfiniteDuration() waits as Await
  // does); returns `done()` at the end.
  template <typename Predicate>
  bool AwaitWithTimeout(Predicate done, absl::Duration timeout)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(this) {
    if (timeout == absl::InfiniteDuration()) {
      Await(done);
      return true;
    }
    std::unique_lock<std::mutex> lock(mutex_, std::adopt_lock);
    ++waiters_;
    const bool result = changed_.wait_for(
        lock, absl::ToChronoNanoseconds(timeout), std::move(done));
    --waiters_;
    lock.release();
    return result;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int waiters_ = 0;  // threads in Await; guarded by mutex_
};

// Holds `mu` for its scope.
class ABSL_SCOPED_LOCKABLE MutexLock {
 public:
  explicit MutexLock(Mutex* mu) ABSL_EXCLUSIVE_LOCK_FUNCTION(mu) : mu_(mu) {
    mu_->Lock();
  }
  ~MutexLock() ABSL_UNLOCK_FUNCTION() { mu_->Unlock(); }

  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

 private:
  Mutex* const mu_;
};

// A one-shot event, like absl::Notification, visible to ThreadSanitizer.
class Notification {
 public:
  void Notify() {
    MutexLock lock(&mu_);
    notified_ = true;
  }
  bool HasBeenNotified() const {
    MutexLock lock(&mu_);
    return notified_;
  }
  void WaitForNotification() const {
    MutexLock lock(&mu_);
    mu_.Await([this]()
                  ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return notified_; });
  }
  // Returns whether it was notified within `timeout`.
  bool WaitForNotificationWithTimeout(absl::Duration timeout) const {
    MutexLock lock(&mu_);
    return mu_.AwaitWithTimeout(
        [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return notified_; },
        timeout);
  }

 private:
  mutable Mutex mu_;
  bool notified_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_MUTEX_H_
