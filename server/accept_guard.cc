#include "server/accept_guard.h"

#include <dlfcn.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <optional>

#include "server/descriptors.h"

namespace fovea::server {
namespace {

using Accept4 = int (*)(int, sockaddr*, socklen_t*, int);

std::atomic<int> reserve{0};
std::atomic<int64_t> refused{0};

// The accept4 this one hides: libc's, or a sanitizer's interceptor of it.
Accept4 NextAccept4() {
  static const Accept4 next =
      reinterpret_cast<Accept4>(dlsym(RTLD_NEXT, "accept4"));
  return next;
}

// True when fewer than `reserve` descriptors are left (or they cannot be
// counted, which near the limit means none are).
bool ShortOfDescriptors(int keep) {
  const std::optional<DescriptorUse> use = CountDescriptors();
  if (!use.has_value()) return true;
  return use->open > use->limit - keep;
}

}  // namespace

void SetAcceptReserve(int keep) { reserve.store(keep < 0 ? 0 : keep); }

int64_t AcceptsRefused() { return refused.load(); }

}  // namespace fovea::server

// See accept_guard.h. At most this many connections are refused in one
// call before it reports EAGAIN (the poller comes back with the next one).
extern "C" int accept4(int sockfd, sockaddr* addr, socklen_t* addrlen,
                       int flags) {
  using fovea::server::refused;
  using fovea::server::reserve;
  const fovea::server::Accept4 next = fovea::server::NextAccept4();
  if (next == nullptr) {
    errno = ENOSYS;
    return -1;
  }
  const int keep = reserve.load();
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const int fd = next(sockfd, addr, addrlen, flags);
    if (keep == 0) return fd;
    if (fd < 0) {
      if (errno == EMFILE || errno == ENFILE) {
        refused.fetch_add(1);
        usleep(20000);
        errno = EAGAIN;
      }
      return -1;
    }
    if (!fovea::server::ShortOfDescriptors(keep)) return fd;
    close(fd);
    refused.fetch_add(1);
  }
  errno = EAGAIN;
  return -1;
}
