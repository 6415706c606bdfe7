// BuildCloudPyramid on a rendered 640x480 scene (synth::GenerateScene(1)).
// Run: build/tests/cloud_pyramid_benchmark

#include <benchmark/benchmark.h>

#include "core/frame/organized_cloud.h"
#include "core/pyramid/cloud_pyramid.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

void BM_BuildCloudPyramid(benchmark::State& state) {
  const synth::SynthScene scene = synth::GenerateScene(1);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  if (!cloud.ok()) {
    state.SkipWithError("BuildOrganizedCloud failed");
    return;
  }
  for (auto _ : state) {
    absl::StatusOr<CloudPyramid> pyramid = BuildCloudPyramid(*cloud, {});
    benchmark::DoNotOptimize(pyramid);
  }
}
BENCHMARK(BM_BuildCloudPyramid)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fovea

BENCHMARK_MAIN();
