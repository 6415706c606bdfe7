#ifndef FOVEA_CORE_BASE_STAGE_CLOCK_H_
#define FOVEA_CORE_BASE_STAGE_CLOCK_H_

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace fovea {

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
      : timings_(timings), start_(Clock::now()) {}
  void Lap(std::string stage) {
    const Clock::time_point now = Clock::now();
    timings_.push_back({std::move(stage),
                        std::chrono::duration<double>(now - start_).count()});
    start_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::vector<StageTiming>& timings_;
  Clock::time_point start_;
};

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_STAGE_CLOCK_H_
