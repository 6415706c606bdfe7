#include "server/descriptors.h"

#include <dirent.h>
#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace fovea::server {

std::optional<DescriptorUse> CountDescriptors() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return std::nullopt;
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return std::nullopt;
  int entries = 0;
  while (const dirent* entry = readdir(dir)) {
    if (entry->d_name[0] != '.') ++entries;
  }
  closedir(dir);
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
