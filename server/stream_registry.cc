#include "server/stream_registry.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/metrics.h"

namespace fovea::server {
namespace {

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             Clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::string PeerAddress(const std::string& peer) {
  const size_t colon = peer.rfind(':');
  const size_t scheme = peer.find(':');
  if (colon == std::string::npos || colon == scheme) return peer;
  return peer.substr(0, colon);
}

void StreamRegistry::Handle::Touch() { last_touch_ns_.store(NowNs()); }

void StreamRegistry::Handle::SetBusy(bool busy) {
  if (!busy) Touch();  // before busy_ reads false: idle from now
  busy_.store(busy);
}

StreamRegistry::StreamRegistry(StreamLimits limits) : limits_(limits) {
  reaper_ = std::thread([this] { Reap(); });
}

StreamRegistry::~StreamRegistry() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  reaper_.join();
}

absl::StatusOr<std::shared_ptr<StreamRegistry::Handle>> StreamRegistry::Open(
    const std::string& peer, std::function<void()> cancel) {
  auto handle = std::make_shared<Handle>();
  handle->peer_ = PeerAddress(peer);
  handle->cancel_ = std::move(cancel);
  handle->Touch();
  std::lock_guard<std::mutex> lock(mutex_);
  if (static_cast<int>(open_.size()) >= limits_.max_streams) {
    return absl::ResourceExhaustedError(
        absl::StrCat("server busy: ", open_.size(),
                     " streams open (--max_track_streams); retry later"));
  }
  int& from_peer = per_peer_[handle->peer_];
  if (from_peer >= limits_.max_streams_per_peer) {
    return absl::ResourceExhaustedError(
        absl::StrCat(from_peer, " streams already open from ", handle->peer_,
                     " (--max_track_streams_per_peer); close one first"));
  }
  ++from_peer;
  open_[handle.get()] = handle;
  return handle;
}

void StreamRegistry::Close(const std::shared_ptr<Handle>& handle) {
  {
    // Waits for a cancel in progress; none starts after this.
    std::lock_guard<std::recursive_mutex> lock(handle->mutex_);
    handle->cancel_ = nullptr;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (open_.erase(handle.get()) == 0) return;
  auto peer = per_peer_.find(handle->peer_);
  if (peer != per_peer_.end() && --peer->second <= 0) per_peer_.erase(peer);
}

int StreamRegistry::open() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(open_.size());
}

void StreamRegistry::Reap() {
  const auto period = std::min<std::chrono::milliseconds>(
      std::chrono::milliseconds(250), limits_.idle_timeout / 4);
  const int64_t idle_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(limits_.idle_timeout)
          .count();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_.wait_for(lock, std::max(period, std::chrono::milliseconds(1)),
                         [this] { return stopping_; })) {
    const int64_t now = NowNs();
    std::vector<std::shared_ptr<Handle>> idle;
    for (const auto& [key, handle] : open_) {
      if (!handle->busy_.load() &&
          now - handle->last_touch_ns_.load() > idle_ns) {
        idle.push_back(handle);
      }
    }
    lock.unlock();
    for (const std::shared_ptr<Handle>& handle : idle) {
      std::lock_guard<std::recursive_mutex> hold(handle->mutex_);
      if (handle->cancel_ && !handle->cancelled_) {
        handle->cancelled_ = true;
        RecordShed(limits_.shed_reason);
        handle->cancel_();
      }
    }
    lock.lock();
  }
}

}  // namespace fovea::server
