#ifndef FOVEA_SERVER_CLOCK_H_
#define FOVEA_SERVER_CLOCK_H_

#include <grpc/support/time.h>

#include <chrono>

#include "core/base/stage_clock.h"

namespace fovea::server {

// The clock of every duration the server measures (calls, stages, queue
// waits): core's (fovea::SteadyClock, fovea::SecondsSince).
using Clock = SteadyClock;

// True once `deadline` (a call's raw deadline, any gpr clock) has passed.
// Compared as gpr_timespec: a deadline past the year 2262 (grpc-timeout
// allows 99999999 hours) overflows the nanosecond std::chrono time_point
// that ServerContext::deadline() returns, and would read as long past.
inline bool DeadlinePassed(gpr_timespec deadline) {
  return gpr_time_cmp(gpr_now(GPR_CLOCK_REALTIME),
                      gpr_convert_clock_type(deadline, GPR_CLOCK_REALTIME)) >=
         0;
}

}  // namespace fovea::server

#endif  // FOVEA_SERVER_CLOCK_H_
