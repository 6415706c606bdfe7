#ifndef FOVEA_TOOLS_BENCH_OBJECT_GEOMETRY_BENCHMARK_H_
#define FOVEA_TOOLS_BENCH_OBJECT_GEOMETRY_BENCHMARK_H_

#include <string>

#include "tools/bench/bench_inputs.h"
#include "tools/bench/stage_benchmarks.h"

namespace fovea::bench {

// "BM_ObjectGeometry<suffix>": the box of each object of a frame on its
// support (FitSupportAlignedBox, as every Segment and SegmentIncremental
// object gets one), for COS's objects with the default options, cut
// before the timing. `scenes` must outlive the benchmark run.
void RegisterObjectGeometryBenchmark(const SceneList* scenes,
                                     const std::string& set,
                                     const std::string& suffix,
                                     const SweepOptions& sweep);

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_OBJECT_GEOMETRY_BENCHMARK_H_
