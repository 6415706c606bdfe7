#ifndef FOVEA_CORE_BASE_TSAN_H_
#define FOVEA_CORE_BASE_TSAN_H_

// Happens-before edges that ThreadSanitizer cannot see on its own, for
// code that hands objects between threads through a library built
// without TSan (Debian's libgrpc++: a reactor made on one of gRPC's
// threads, its reactions and its deletion on others, ordered by locks
// inside libgrpc). In builds without TSan both functions are empty.
//
// TsanHappensBefore(p) on one thread, then TsanHappensAfter(p) on another:
// everything the first thread did before the call happens before
// everything the second does after its call, as if a mutex at `p` had
// been released and then acquired. Only state the library really orders
// may be annotated: the annotation hides a race, it cannot prevent one.

#if defined(__SANITIZE_THREAD__)
#define FOVEA_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define FOVEA_TSAN 1
#endif
#endif

#ifdef FOVEA_TSAN
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace fovea {

inline void TsanHappensBefore([[maybe_unused]] const void* p) {
#ifdef FOVEA_TSAN
  __tsan_release(const_cast<void*>(p));
#endif
}

inline void TsanHappensAfter([[maybe_unused]] const void* p) {
#ifdef FOVEA_TSAN
  __tsan_acquire(const_cast<void*>(p));
#endif
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_TSAN_H_
