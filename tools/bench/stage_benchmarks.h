#ifndef FOVEA_TOOLS_BENCH_STAGE_BENCHMARKS_H_
#define FOVEA_TOOLS_BENCH_STAGE_BENCHMARKS_H_

#include <benchmark/benchmark.h>

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/pipeline/models.h"
#include "tools/bench/bench_inputs.h"

namespace fovea::bench {

// How a scene set is swept. Every iteration handles one scene, round-robin,
// and a repetition runs a whole number of passes over the set, so each
// repetition's mean is the mean over all of its scenes (with an automatic
// iteration count, a 45-scene set and a 30 ms case would time only the
// first 17 scenes). `passes` <= 0: as many passes as make a repetition last
// about `target_repetition_seconds`, from each case's expected cost.
struct SweepOptions {
  int passes = 0;
  double target_repetition_seconds = 0.5;
};

// The models of the source tree's models/ (the server's default), loaded
// once.
const absl::StatusOr<LoadedModels>& BenchModels();

// Iterations for one repetition of a case expected to take `expected_ms`
// per frame on `scene_count` scenes: a multiple of `scene_count`.
int64_t SweepIterations(const SweepOptions& sweep, int scene_count,
                        double expected_ms);

// Sweeps `scenes` with `body` (called once per iteration with the scene);
// the first non-OK status skips the case with that error. Labels the case
// with the scene count and `set_name`.
void SweepScenes(benchmark::State& state, const SceneList& scenes,
                 std::string_view set_name,
                 const std::function<absl::Status(const BenchScene&)>& body);

// Registers every in-process case (decode, cloud, normals, support plane,
// frame preparation, each saliency operator, surface edges, planar patches,
// surface models, EBS edge probability and contour, MSR, Detect, Segment,
// the object boxes (object_geometry_benchmark.h), the whole-scene PCL peers
// BM_PeerEuclidean and BM_PeerLccp) on `scenes`, named "BM_<Stage><suffix>" or
// "BM_Detect/<ops><suffix>"; `suffix` is "" for the synthetic set and "/osd"
// for the OSD set. `scenes` must outlive the benchmark run. Nothing is
// registered for an empty set.
void RegisterStageBenchmarks(const SceneList* scenes,
                             const std::string& set_name,
                             const std::string& suffix,
                             const SweepOptions& sweep);

// Rough per-frame cost of a whole Detect and a whole INC segmentation on
// one core, milliseconds; only sizes the number of passes per repetition
// (SweepIterations).
inline constexpr double kDetectMs = 30.0;
inline constexpr double kSegmentMs = 60.0;

// What a benchmark case does with one scene.
using SceneBody = std::function<absl::Status(const BenchScene&)>;

// Registers benchmark `name`: `body` over every scene of `scenes` per
// iteration (SweepScenes), as many iterations as `sweep` and
// `expected_ms` per frame ask (SweepIterations), in milliseconds.
void Register(const std::string& name, const SceneList* scenes,
              const std::string& set_name, const SweepOptions& sweep,
              double expected_ms, SceneBody body);

// Whole requests from the raw wire frame, as the server runs them in
// process: decode, then Detect ("BM_Frame/detect/<set>") or
// SegmentIncremental to the end of the scene ("BM_Frame/inc/<set>"), each
// with default options. Registered for each set of `sets` (name, scenes)
// in order, so that frames of different resolutions are timed in one run.
void RegisterFrameCases(
    const std::vector<std::pair<std::string, const SceneList*>>& sets,
    const SweepOptions& sweep);

// The saliency channel sets of the Detect cases: "ph", "sh", "rso",
// "ph+sh+rso".
inline constexpr std::string_view kDetectChannelSets[] = {"ph", "sh", "rso",
                                                          "ph+sh+rso"};

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_STAGE_BENCHMARKS_H_
