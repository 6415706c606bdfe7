// OpenCV's parallel_for_ backend on fovea's ParallelFor (parallel.h).

#include <memory>
#include <opencv2/core/parallel/parallel_backend.hpp>

#include "core/base/parallel.h"

namespace fovea {
namespace {

class ScopedBackend : public cv::parallel::ParallelForAPI {
 public:
  // OpenCV cuts a loop into `tasks` stripes; body(begin, end) runs stripes
  // [begin, end). In a few contiguous ranges, so that a serial scope makes
  // one call, as OpenCV's own serial path does (a filter sets up its row
  // buffers once per call, not once per stripe).
  void parallel_for(int tasks, FN_parallel_for_body_cb_t body,
                    void* data) override {
    ParallelForRanges(tasks,
                      [&](int begin, int end) { body(begin, end, data); });
  }
  int getThreadNum() const override { return ParallelThreadIndex(); }
  // OpenCV splits a loop into about this many stripes.
  int getNumThreads() const override { return ParallelThreads(); }
  int setNumThreads(int) override { return ParallelThreads(); }
  const char* getName() const override { return "fovea-parallel-scope"; }
};

}  // namespace

void UseParallelScopesInOpenCv() {
  cv::parallel::setParallelForBackend(std::make_shared<ScopedBackend>(),
                                      /*propagateNumThreads=*/false);
}

}  // namespace fovea
