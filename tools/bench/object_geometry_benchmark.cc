#include "tools/bench/object_geometry_benchmark.h"

#include <unordered_map>
#include <utility>
#include <vector>

#include "core/base/status_macros.h"
#include "core/pipeline/models.h"
#include "core/pipeline/object_geometry.h"
#include "core/pipeline/segment.h"

namespace fovea::bench {
namespace {

// Rough per-frame cost of the case on one core, milliseconds (sizes its
// iterations).
constexpr double kObjectGeometryMs = 1.0;

// A frame's support and its objects' points (COS, default options).
struct SceneObjects {
  SupportPlane plane;
  std::vector<std::vector<Eigen::Vector3f>> points;
};

absl::StatusOr<SceneObjects> CutObjects(const BenchScene& scene) {
  const absl::StatusOr<LoadedModels>& models = BenchModels();
  if (!models.ok()) return models.status();
  SceneObjects objects;
  SegmentSinks sinks;
  sinks.support = [&objects](const SupportPlane& plane) {
    objects.plane = plane;
    return absl::OkStatus();
  };
  sinks.object = [&objects, &scene](SegmentedObject object) {
    objects.points.push_back(MaskPoints(scene.cloud, object.mask, object.box));
    return absl::OkStatus();
  };
  FOVEA_RETURN_IF_ERROR(
      RunSegment(scene.frame, SegmentOptions{}, models->View(), sinks)
          .status());
  return objects;
}

}  // namespace

void RegisterObjectGeometryBenchmark(const SceneList* scenes,
                                     const std::string& set,
                                     const std::string& suffix,
                                     const SweepOptions& sweep) {
  benchmark::RegisterBenchmark(
      ("BM_ObjectGeometry" + suffix).c_str(),
      [scenes, set](benchmark::State& state) {
        std::unordered_map<const BenchScene*, SceneObjects> cut;
        for (const auto& scene : *scenes) {
          absl::StatusOr<SceneObjects> objects = CutObjects(*scene);
          if (!objects.ok()) {
            state.SkipWithError(objects.status().ToString().c_str());
            return;
          }
          cut.emplace(scene.get(), *std::move(objects));
        }
        SweepScenes(state, *scenes, set, [&](const BenchScene& scene) {
          const SceneObjects& objects = cut.at(&scene);
          for (const auto& points : objects.points) {
            absl::StatusOr<ObjectGeometry> box =
                FitSupportAlignedBox(points, objects.plane);
            benchmark::DoNotOptimize(box);
          }
          return absl::OkStatus();
        });
      })
      ->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                   kObjectGeometryMs))
      ->Unit(benchmark::kMillisecond);
}

}  // namespace fovea::bench
