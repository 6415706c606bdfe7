#ifndef FOVEA_CORE_BASE_STAGE_CLOCK_H_
#define FOVEA_CORE_BASE_STAGE_CLOCK_H_

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace fovea {

// The clock of every duration Fovea measures (stages, calls, queue waits):
// monotonic, unaffected by changes to the wall clock.
using SteadyClock = std::chrono::steady_clock;

// Seconds from `start` to now.
inline double SecondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// How long one stage of a request took, wall clock.
struct StageTiming {
  std::string stage;  // "cloud", "normals", "saliency.sym3d", "inc.relations"
  double seconds = 0.0;
};

// Wall-clock stage timer that appends to `timings`: each Lap records the
// time since the previous one (or since construction) under its name.
class StageClock {
 public:
  explicit StageClock(std::vector<StageTiming>& timings)
      : timings_(timings), start_(SteadyClock::now()) {}
  void Lap(std::string stage) {
    const SteadyClock::time_point now = SteadyClock::now();
    timings_.push_back({std::move(stage),
                        std::chrono::duration<double>(now - start_).count()});
    start_ = now;
  }

 private:
  std::vector<StageTiming>& timings_;
  SteadyClock::time_point start_;
};

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_STAGE_CLOCK_H_
