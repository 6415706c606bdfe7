#ifndef FOVEA_SERVER_STREAM_REGISTRY_H_
#define FOVEA_SERVER_STREAM_REGISTRY_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "server/clock.h"

namespace fovea::server {

// How many long-lived streams (Track) the server holds, and for how long
// one may sit idle: a stream is a new way to hold a server.
struct StreamLimits {
  int max_streams = 64;          // open at once, all peers
  int max_streams_per_peer = 8;  // open at once from one peer address
  // A stream whose client sent nothing for this long, while the server
  // owed it nothing, is cancelled.
  std::chrono::milliseconds idle_timeout{10000};
  // fovea_calls_shed_total's reason for a stream cancelled so.
  std::string_view shed_reason = "idle_stream";
};

// The open streams: admits a new one against the limits, and cancels those
// whose client has been idle too long (from its own thread, every quarter
// of the idle timeout, at most 250 ms apart). Thread-safe.
class StreamRegistry {
 public:
  explicit StreamRegistry(StreamLimits limits);
  ~StreamRegistry();
  StreamRegistry(const StreamRegistry&) = delete;
  StreamRegistry& operator=(const StreamRegistry&) = delete;

  // One open stream, shared by its reactor and the registry. `cancel`
  // cancels the call; it is run only while the stream is open (Close
  // waits for a cancel in progress), under the handle's own lock.
  class Handle {
   public:
    // The client sent something: the stream is not idle.
    void Touch();
    // The server is working for the stream (a frame queued or being
    // processed): not idle, however long its client waits for the answer.
    // Once set back to false, the idle time counts from then.
    void SetBusy(bool busy);

   private:
    friend class StreamRegistry;
    std::recursive_mutex mutex_;
    std::function<void()> cancel_;  // guarded by mutex_; empty once closed
    std::string peer_;
    std::atomic<int64_t> last_touch_ns_{0};
    std::atomic<bool> busy_{false};
    bool cancelled_ = false;  // guarded by mutex_
  };

  // Admits a stream from `peer` (its address without the port counts as
  // one peer): RESOURCE_EXHAUSTED naming the limit when one is reached.
  absl::StatusOr<std::shared_ptr<Handle>> Open(const std::string& peer,
                                               std::function<void()> cancel);
  // The stream ended: never cancelled after this returns.
  void Close(const std::shared_ptr<Handle>& handle);

  int open() const;
  const StreamLimits& limits() const { return limits_; }

 private:
  void Reap();

  const StreamLimits limits_;
  mutable std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;                            // guarded by mutex_
  std::map<Handle*, std::shared_ptr<Handle>> open_;  // guarded by mutex_
  std::map<std::string, int> per_peer_;              // guarded by mutex_
  std::thread reaper_;
};

// The peer's address without its port ("ipv4:10.0.0.5:41234" ->
// "ipv4:10.0.0.5"; "ipv6:[::1]:5000" -> "ipv6:[::1]").
std::string PeerAddress(const std::string& peer);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_STREAM_REGISTRY_H_
