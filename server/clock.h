#ifndef FOVEA_SERVER_CLOCK_H_
#define FOVEA_SERVER_CLOCK_H_

#include <chrono>

namespace fovea::server {

// The clock of every duration the server measures (calls, stages, queue
// waits): monotonic, unaffected by changes to the wall clock.
using Clock = std::chrono::steady_clock;

// Seconds from `start` to now.
inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace fovea::server

#endif  // FOVEA_SERVER_CLOCK_H_
