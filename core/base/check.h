#ifndef FOVEA_CORE_BASE_CHECK_H_
#define FOVEA_CORE_BASE_CHECK_H_

#include <cstdio>
#include <cstdlib>

// FOVEA_CHECK(condition): a broken internal assumption (a bug, never bad
// input) prints where and aborts. Debian 12's abseil (20220623) predates
// absl/log/check.h, which ../shared/STYLE.md names; this is its stand-in.
// Bad input is reported with absl::Status, never with a check.
#define FOVEA_CHECK(condition)                                          \
  do {                                                                  \
    if (!(condition)) {                                                 \
      std::fprintf(stderr, "%s:%d: FOVEA_CHECK failed: %s\n", __FILE__, \
                   __LINE__, #condition);                               \
      std::abort();                                                     \
    }                                                                   \
  } while (false)

#endif  // FOVEA_CORE_BASE_CHECK_H_
