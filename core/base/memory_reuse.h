#ifndef FOVEA_CORE_BASE_MEMORY_REUSE_H_
#define FOVEA_CORE_BASE_MEMORY_REUSE_H_

#include <cstddef>

namespace fovea {

// Most of a request's memory is a few blocks of megabytes (the cloud, its
// normals, label images), allocated and freed once per frame. By default
// glibc hands blocks that large back to the kernel when they are freed
// (mmap, or trimming the heap), so the next frame takes a page fault per
// 4 KiB of them again: 2-3 ms of a 640x480 frame's 30. This keeps them:
// blocks below `largest_block` bytes come from the heap, and up to
// `kept_bytes` of free heap stay mapped for the next request. A process's
// resident memory then stays near its busiest moment instead of falling
// back between requests. glibc only; call once, early in main, before
// other threads start.
void ReuseFreedMemory(size_t largest_block = size_t{32} << 20,
                      size_t kept_bytes = size_t{256} << 20);

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_MEMORY_REUSE_H_
