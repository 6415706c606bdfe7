// OpenCV's parallel_for_ backend on fovea's ParallelFor (parallel.h).

#include <memory>
#include <opencv2/core/parallel/parallel_backend.hpp>

#include "core/base/parallel.h"

namespace fovea {
namespace {

class ScopedBackend : public cv::parallel::ParallelForAPI {
 public:
  void parallel_for(int tasks, FN_parallel_for_body_cb_t body,
                    void* data) override {
    ParallelFor(tasks, [&](int i) { body(i, i + 1, data); });
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
