// fovea-eval: detection quality on labelled OSD-format scenes, in-process.
//
//   fovea-eval detect --data DIR [--saliency ph|sh|rso|ph+sh+rso]
//                     [--extract msr] [--json] [--out DIR] [--verbose]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "core/base/memory_reuse.h"
#include "core/base/parallel.h"
#include "core/frame/sensor_model.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/models.h"
#include "core/pipeline/saliency_registry.h"
#include "core/segmentation/svm_training.h"
#include "core/synth/synth_scene.h"
#ifdef FOVEA_EVAL_REPLAY
#include "tools/eval/replay.h"
#endif
#include "core/pipeline/incremental.h"
#include "core/synth/replayed_scene.h"
#include "core/synth/sequence.h"
#include "core/track/tracker.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/inc_eval.h"
#include "tools/eval/json_lines.h"
#include "tools/eval/methods_eval.h"
#include "tools/eval/raw_frame_eval.h"
#include "tools/eval/room_eval.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/scene_runner.h"
#include "tools/eval/scorecard.h"
#include "tools/eval/sweep.h"

ABSL_FLAG(std::string, data, "",
          "OSD-format folder: *.pcd files, or a folder with learn/ inside. "
          "Defaults to $FOVEA_OSD_DIR.");
ABSL_FLAG(std::string, saliency,
          fovea::ChannelsText(fovea::DetectOptions().channels),
          absl::StrCat("Saliency channels: ", fovea::SaliencyOperatorNames(),
                       ", or a combination like ph+sh+rso (equal weights); or "
                       "pcl-clusters, the peer: Euclidean clusters on the "
                       "support plane, largest first (ignores --extract)."));
ABSL_FLAG(std::string, extract,
          std::string(fovea::ExtractionName(fovea::DetectOptions().extraction)),
          absl::StrCat("Attention-point extraction: ",
                       fovea::ExtractionNames(", "), "."));
ABSL_FLAG(int, points, fovea::DetectOptions().max_points,
          "Attention points per scene at most. HR counts the first "
          "max(K, 10) of them for a scene of K objects, as the thesis's "
          "tables do, whatever this is; hit_ratio_all_points counts every "
          "point returned.");
ABSL_FLAG(std::string, pyramid,
          std::string(fovea::PyramidName(fovea::DetectOptions().pyramid)),
          absl::StrCat("Pyramid: ",
                       fovea::NameList(fovea::PyramidKinds(), ", "), "."));
ABSL_FLAG(std::string, combine, "sum",
          absl::StrCat("Across-scale combination with a pyramid: ",
                       fovea::NameList(fovea::LevelCombinations(), ", "), "."));
ABSL_FLAG(std::string, norm, "lin",
          absl::StrCat("Map normalisation: ",
                       fovea::NameList(fovea::NormalizationKinds(), ", "),
                       "."));
ABSL_FLAG(std::string, fusion, "sum",
          absl::StrCat("Channel fusion: ",
                       fovea::NameList(fovea::FusionKinds(), ", "), "."));
ABSL_FLAG(int, sym3d_level, fovea::DetectOptions().sym3d_level,
          "Pyramid level SYM3D runs on without a pyramid.");
ABSL_FLAG(int, sym3d_kernel, fovea::DetectOptions().sym3d.kernel_size,
          "SYM3D kernel size, pixels of its level.");
ABSL_FLAG(double, tj_support, fovea::DetectOptions().tj.support_fraction,
          "TJ: components of the pixels at or above this fraction of the "
          "maximum (0: above zero, as the thesis).");
ABSL_FLAG(std::string, tj_junction, "central",
          "TJ: of several skeleton junctions take the one nearest the "
          "component's centroid (central) or the most salient (salient).");
ABSL_FLAG(std::string, tj_rank, "total",
          "TJ: rank components by total saliency (total) or by mean saliency "
          "(mean, the thesis).");
ABSL_FLAG(bool, split_edges, fovea::DetectOptions().split_at_surface_edges,
          "Zero the master map on occluding edges and concave creases "
          "before extraction (touching objects become separate components).");
ABSL_FLAG(double, edge_jump,
          fovea::DetectOptions().surface_edges.depth_jump_fraction,
          "Surface edges: depth jump, fraction of depth (0: off).");
ABSL_FLAG(double, edge_concave,
          fovea::DetectOptions().surface_edges.concave_curvature,
          "Surface edges: concave crease threshold (0: off).");
ABSL_FLAG(double, edge_concave_sharpness,
          fovea::DetectOptions().surface_edges.concave_min_curvature,
          "Surface edges: a crease's least curvature, 1/m (0: any fold).");
ABSL_FLAG(int, edge_radius, fovea::DetectOptions().surface_edges.radius_px,
          "Surface edges: neighbour distance, pixels at f = 525 px.");
ABSL_FLAG(bool, msr_inhibit_slope, true,
          "MSR also inhibits the slope around each region (false = exactly "
          "the thesis's MSR).");
ABSL_FLAG(bool, fill_holes, false,
          "Fill small depth holes by colour-guided diffusion first "
          "(thesis section 2.2).");
ABSL_FLAG(std::string, sensor,
          std::string(fovea::SensorKindName(fovea::SceneOptions().sensor)),
          absl::StrCat("Depth noise model the thresholds follow: ",
                       fovea::NameList(fovea::SensorKinds(), ", "),
                       " (generic: chosen from the intrinsics)."));
ABSL_FLAG(int, processing_width, fovea::SceneOptions().processing_width,
          "Frames wider than this are processed reduced, pixels.");
ABSL_FLAG(bool, json, false,
          "Also print JSON, one object per line: detect a last line with "
          "scenes, hit_ratio, distance_to_center, hit_ratio_at, "
          "detect_ms_median, ...; segment one per method, rooms one per "
          "group, raw one per frame (keys: tools/eval/json_lines.h). A number "
          "that is not finite (NaN, infinity) is null, as JSON has neither.");
ABSL_FLAG(std::string, out, "",
          "Write <scene>.png (colour with object outlines | saliency map, "
          "points numbered) into this folder.");
ABSL_FLAG(bool, verbose, false, "One line per scene on stderr.");
ABSL_FLAG(std::string, method, "cos",
          absl::StrCat("segment: ",
                       fovea::NameList(fovea::eval::SceneMethods(), ", "),
                       "; several of them comma-separated (one run, side by "
                       "side), or all."));
ABSL_FLAG(std::string, inc_saliency, "sym3d",
          "segment --method inc: sym3d (Detect's map, F from one run) or "
          "random-points (per object 5 sequences of 5 points, section 3.3.3).");
ABSL_FLAG(std::string, seeds, "",
          absl::StrCat("segment: where the seeds come from, ",
                       fovea::ExtractionNames(", "),
                       " (Detect's extraction; overrides --extract)."));
ABSL_FLAG(int, folds, 0,
          "segment: 0 scores the models as shipped (--models); K >= 2 "
          "cross-validates instead: scene i is scored with models trained on "
          "the scenes of the other K - 1 folds.");
ABSL_FLAG(bool, cover_scene, true,
          "segment --method cos / ebs: after the attention points, seed the "
          "surfaces no mask holds yet (the server's default for all "
          "objects); false: the attention points' objects only.");
ABSL_FLAG(double, svm_c, fovea::LinearSvmTrainingOptions().c,
          "segment: the COS SVM's soft-margin penalty C.");
ABSL_FLAG(int, count, 200,
          "rooms: rooms per sensor and size; track: sequences per kind.");
ABSL_FLAG(int, piles, 0,
          "detect / segment: evaluate on this many synthetic piles (8-16 "
          "household objects each, seeds from --seed) instead of --data.");
ABSL_FLAG(uint64_t, seed, 1, "rooms: the first room's seed.");
ABSL_FLAG(std::string, room_sensors, "kinect_v1,active_stereo",
          absl::StrCat("rooms: sensor noise models to render with, "
                       "comma-separated (",
                       fovea::NameList(fovea::SensorKinds(), ", "), ")."));
ABSL_FLAG(std::string, sizes, "640x480",
          "rooms: resolutions, comma-separated WxH (e.g. 640x480,1280x720).");
ABSL_FLAG(std::string, models, FOVEA_DEFAULT_MODELS_DIR,
          "segment, rooms, raw: the trained models, as the server loads "
          "them.");
ABSL_FLAG(std::string, server, "",
          "replay: the server the recorded calls go to, HOST:PORT (or any "
          "fovea-client target).");
ABSL_FLAG(bool, fail_on_change, false,
          "replay: exit 3 when any record's answer changed.");
ABSL_FLAG(int, track_frames, 12, "track: frames per sequence.");
ABSL_FLAG(std::string, kinds, "",
          absl::StrCat("track: sequence kinds, comma-separated (",
                       fovea::NameList(fovea::synth::SequenceKinds(), ", "),
                       "; and real OSD scenes replayed: osd-",
                       fovea::NameList(fovea::synth::ReplayKinds(), ", osd-"),
                       ", from --data); empty: all (the osd ones when there "
                       "is data)."));
ABSL_FLAG(bool, pose, true,
          "track: send each frame's camera pose (false: the tracker "
          "anchors on the scene alone).");
ABSL_FLAG(double, reidentify_distance,
          fovea::TrackerOptions().reidentify_distance,
          "track: the tracker's re-identification threshold (Bhattacharyya "
          "distance of colour histograms); 0 turns re-identification off.");
ABSL_FLAG(bool, reuse_regions, fovea::TrackerOptions().reuse_regions,
          "track: segment only the region that changed when the camera is "
          "still, keeping the objects outside it (TrackerOptions::"
          "reuse_regions); false segments every changed frame whole");
ABSL_FLAG(int, region_whole_every, fovea::TrackerOptions().region_whole_every,
          "track: after this many region-only segmentations in a row the "
          "next changed frame is segmented whole (TrackerOptions::"
          "region_whole_every).");
ABSL_FLAG(double, change_weight, fovea::IncrementalOptions().change_weight,
          "track: the weight of the temporal cue (what changed since the "
          "last frame) in INC's saliency; 0 turns it off.");
ABSL_FLAG(std::string, filter, "",
          "sweep: only the rows whose label saliency/pyramid/combine/norm/"
          "extract contains this.");

#include "tools/eval/commands.h"

namespace fovea::eval {
namespace {

// The commands in the order the usage lists them; the usage and the
// unknown-command error are made from this table, and the lists of names
// in it from core's tables (name_table.h), so they say what is built.
struct Command {
  std::string_view name;
  std::string arguments;  // after the name in the usage
  std::string_view summary;
  int (*run)(const std::vector<char*>& args);
};

std::string Alternatives(const std::string& names) {
  return absl::StrJoin(absl::StrSplit(names, ' ', absl::SkipEmpty()), "|");
}

#ifdef FOVEA_EVAL_REPLAY
int RunReplayCommand(const std::vector<char*>& args) {
  ReplayOptions options;
  options.server = absl::GetFlag(FLAGS_server);
  return RunReplay(args.size() > 2 ? args[2] : "", options,
                   absl::GetFlag(FLAGS_json),
                   absl::GetFlag(FLAGS_fail_on_change));
}
#endif

std::vector<Command> Commands() {
  const std::string extractions = Alternatives(ExtractionNames());
  return {
      {"detect",
       absl::StrCat("--data DIR [--saliency ",
                    Alternatives(SaliencyOperatorNames()),
                    "|ph+sh+rso|pcl-clusters|...] [--pyramid ",
                    NameList(PyramidKinds(), "|"), "] [--combine ",
                    NameList(LevelCombinations(), "|"), "] [--norm ",
                    NameList(NormalizationKinds(), "|"), "] [--extract ",
                    extractions, "] [--json] [--out DIR]"),
       "attention points against the labels (Tables 2.4/2.5)",
       [](const std::vector<char*>&) { return RunDetectEval(); }},
      {"sweep", "--data DIR --out DIR [--filter TEXT]",
       "the grid of Tables 2.4/2.5 as Markdown and CSV",
       [](const std::vector<char*>&) { return RunSweepCommand(); }},
      {"segment",
       absl::StrCat("--method ", NameList(SceneMethods(), "|"),
                    " --data DIR [--seeds ", extractions,
                    "] [--inc_saliency sym3d|random-points] [--folds 5] "
                    "[--json] [--out DIR]"),
       "Table 3.1; --folds cross-validates",
       [](const std::vector<char*>&) { return RunSegmentEval(); }},
      {"rooms",
       absl::StrCat("[--count 200] [--seed 1] [--room_sensors ",
                    NameList(SensorKinds(), ","),
                    "] [--sizes 640x480,1280x720] [--method ",
                    NameList(SceneMethods(), "|"),
                    "] [--models DIR] [--json] [--out DIR]"),
       "synthetic rooms, held out: support, recall, false objects",
       [](const std::vector<char*>&) { return RunRoomsCommand(); }},
      {"raw",
       absl::StrCat("--data DIR [--method ", NameList(SceneMethods(), "|"),
                    "]"),
       "each raw frames/<scene>_*.png against its cropped learn/<scene>.pcd",
       [](const std::vector<char*>&) { return RunRawCommand(); }},
#ifdef FOVEA_EVAL_REPLAY
      {"replay", "DIR --server HOST:PORT [--json] [--fail_on_change]",
       "the calls fovea-server --record_dir kept, sent again: points moved, "
       "masks' IoU, objects found or lost, time",
       &RunReplayCommand},
#endif
      {"track",
       absl::StrCat("[--kinds ", NameList(synth::SequenceKinds(), ","),
                    "] [--count 20] [--track_frames 12] [--seed 1] "
                    "[--pose=false] [--json]"),
       "synthetic frame streams with identities: IDF1, switches, overlap F "
       "beside single-frame INC, cost per frame",
       [](const std::vector<char*>&) { return RunTrackCommand(); }},
      {"realism",
       "[--data DIR] [--realsense DIR] [--synthetic 20] [--json] "
       "[--verbose]",
       "synthetic frames of each sensor against its real ones: depth noise "
       "against range, missing depth, normals, the table scene, patches and "
       "relation features; one KS distance per statistic",
       [](const std::vector<char*>&) { return RunRealismCommand(); }},
      {"scorecard",
       "[--short] [--sets osd,...] [--methods inc,cos] [--baseline "
       "docs/scorecard.json] [--write_json F] [--out DIR]",
       "every kind of scene in one table; exit 3 when a figure fell below "
       "the baseline",
       [](const std::vector<char*>&) { return RunScorecardCommand(); }},
  };
}

std::string Usage() {
  std::string usage = "Quality figures on labelled and synthetic scenes.\n";
  for (const Command& row : Commands()) {
    absl::StrAppend(&usage, "  fovea-eval ", AbslView(row.name), " ",
                    row.arguments, "\n      (", AbslView(row.summary), ")\n");
  }
  return usage;
}

}  // namespace
}  // namespace fovea::eval

int main(int argc, char** argv) {
  // As fovea-server does, so that the times measured are the server's:
  // OpenCV's loops on the request's threads, and a frame's large blocks
  // kept mapped for the next (without it, the first of two calls on a
  // frame paid its page faults again, and ran about 30 % slower).
  fovea::UseParallelScopesInOpenCv();
  fovea::ReuseFreedMemory();
  const std::string usage = fovea::eval::Usage();
  absl::SetProgramUsageMessage(usage);
  std::vector<char*> args = absl::ParseCommandLine(argc, argv);
  if (args.size() < 2) {
    std::fprintf(stderr, "%s\n", usage.c_str());
    return fovea::eval::kUsageError;
  }
  const std::string command = args[1];
  std::vector<absl::string_view> known;
  for (const fovea::eval::Command& row : fovea::eval::Commands()) {
    if (command == row.name) return row.run(args);
    known.push_back(fovea::AbslView(row.name));
  }
  std::fprintf(stderr, "fovea-eval: unknown command '%s' (%s)\n%s\n",
               command.c_str(), absl::StrJoin(known, ", ").c_str(),
               usage.c_str());
  return fovea::eval::kUsageError;
}
