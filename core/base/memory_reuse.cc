#include "core/base/memory_reuse.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fovea {

void ReuseFreedMemory(size_t largest_block, size_t kept_bytes) {
#if defined(__GLIBC__)
  // Setting either turns glibc's dynamic thresholds off.
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(largest_block));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(kept_bytes));
#else
  (void)largest_block;
  (void)kept_bytes;
#endif
}

}  // namespace fovea
