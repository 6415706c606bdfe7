#include "server/descriptors.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace fovea::server {

std::optional<DescriptorUse> CountDescriptors() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return std::nullopt;
  // Raw system calls, not opendir: the count runs beside gRPC's threads,
  // which open and close sockets where ThreadSanitizer cannot see it, and
  // a descriptor the sanitizer saw here would look reused without order.
  const long dir = syscall(SYS_openat, AT_FDCWD, "/proc/self/fd",
                           O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) return std::nullopt;
  int entries = 0;
  alignas(8) char buffer[4096];
  while (true) {
    const long n = syscall(SYS_getdents64, dir, buffer, sizeof(buffer));
    if (n <= 0) break;
    for (long at = 0; at < n;) {
      const auto* entry = reinterpret_cast<const dirent64*>(buffer + at);
      if (entry->d_name[0] != '.') ++entries;
      at += entry->d_reclen;
    }
  }
  syscall(SYS_close, dir);
  DescriptorUse use;
  use.open = entries - 1;  // the directory's own descriptor
  use.limit = limit.rlim_cur == RLIM_INFINITY
                  ? 1 << 30
                  : static_cast<int>(std::min<rlim_t>(limit.rlim_cur, 1 << 30));
  return use;
}

std::string RaiseDescriptorLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) {
    return absl::StrCat("file descriptor limit unknown: ",
                        std::strerror(errno));
  }
  if (limit.rlim_cur >= limit.rlim_max) {
    return absl::StrCat("file descriptor limit ", limit.rlim_cur,
                        " (already the hard limit)");
  }
  const rlim_t before = limit.rlim_cur;
  limit.rlim_cur = limit.rlim_max;
  if (setrlimit(RLIMIT_NOFILE, &limit) != 0) {
    return absl::StrCat("file descriptor limit ", before,
                        " (raising it failed: ", std::strerror(errno), ")");
  }
  return absl::StrCat("file descriptor limit raised from ", before, " to ",
                      limit.rlim_max);
}

}  // namespace fovea::server
