#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/pipeline/segment.h"
#include "tools/bench/stage_benchmarks.h"

// BM_Frame: whole requests from the raw wire frame (stage_benchmarks.h).

namespace fovea::bench {

void RegisterFrameCases(
    const std::vector<std::pair<std::string, const SceneList*>>& sets,
    const SweepOptions& sweep) {
  for (const auto& [name, scenes] : sets) {
    if (scenes->empty()) continue;
    // Detect, and beside it without what rests beyond the visible table's
    // hull (TableSceneOptions::rest_beyond_hull_m 0: the table scene as it
    // was before it): what that costs.
    for (const bool beyond : {true, false}) {
      DetectOptions options;
      if (!beyond) options.table_scene.rest_beyond_hull_m = 0.0f;
      Register(
          absl::StrCat("BM_Frame/detect",
                       beyond ? "" : "_without_rest_beyond_hull", "/", name),
          scenes, name, sweep, kDetectMs, [options](const BenchScene& scene) {
            FOVEA_ASSIGN_OR_RETURN(
                RgbdFrame frame,
                DecodeFrame(scene.raw_wire, BenchFrameLimits()));
            absl::StatusOr<DetectResult> result = RunDetect(frame, options);
            benchmark::DoNotOptimize(result);
            return result.status();
          });
    }
    // Whole-scene INC, and beside it without the pieces within an object's
    // footprint joining it (IncOptions::pieces_within), without a body's
    // cross-section in the footprint, without what rests beyond the
    // visible table's hull, without each object checked as a whole
    // (IncOptions::whole_object), without what rests on a face kept apart
    // (IncOptions::resting_on_face), without one face joined across what
    // stands in front of it (IncOptions::across_occluder), or with the base
    // INC model instead of the frame's sensor family's
    // (SegmentModels::IncFor; the same on Kinect frames): what each costs.
    const struct {
      const char* suffix;
      bool pieces, body, beyond, whole, family, resting = true, across = true;
    } variants[] = {
        {"", true, true, true, true, true},
        {"_without_pieces", false, false, true, true, true},
        {"_without_body_footprint", true, false, true, true, true},
        {"_without_rest_beyond_hull", true, true, false, true, true},
        {"_without_whole_object", true, true, true, false, true},
        {"_without_resting_on_face", true, true, true, true, true, false},
        {"_without_across_occluder", true, true, true, true, true, true, false},
        {"_with_base_model", true, true, true, true, false}};
    const IncrementalOptions defaults;
    for (const auto& variant : variants) {
      IncrementalOptions options = defaults;
      options.inc.pieces_within.enabled = variant.pieces;
      options.inc.pieces_within.body_footprint = variant.body;
      options.inc.whole_object.enabled = variant.whole;
      options.inc.resting_on_face.enabled = variant.resting;
      options.inc.across_occluder.enabled = variant.across;
      if (!variant.beyond) options.detect.table_scene.rest_beyond_hull_m = 0.0f;
      const bool family = variant.family;
      Register(
          absl::StrCat("BM_Frame/inc", variant.suffix, "/", name), scenes, name,
          sweep, kSegmentMs, [options, family](const BenchScene& scene) {
            const absl::StatusOr<LoadedModels>& models = BenchModels();
            if (!models.ok()) return models.status();
            FOVEA_ASSIGN_OR_RETURN(
                RgbdFrame frame,
                DecodeFrame(scene.raw_wire, BenchFrameLimits()));
            const SegmentModels view = models->View();
            absl::StatusOr<SegmentSummary> summary = RunSegmentIncremental(
                frame, options,
                family ? view.IncFor(frame, options.detect.scene) : view.inc,
                SegmentSinks{});
            benchmark::DoNotOptimize(summary);
            return summary.status();
          });
    }
  }
}

}  // namespace fovea::bench
