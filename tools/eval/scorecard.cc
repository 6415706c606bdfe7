// fovea-eval scorecard: every kind of scene in one run (scorecard.h).

#include "tools/eval/scorecard.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/eval/detection_metrics.h"
#include "core/eval/uois_metrics.h"
#include "core/frame/frame_transform.h"
#include "core/frame/organized_cloud.h"
#include "core/pipeline/incremental.h"
#include "core/segmentation/relations.h"
#include "core/segmentation/svm_training.h"
#include "core/synth/osd_crop.h"
#include "core/synth/room.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/methods_eval.h"
#include "tools/eval/realsense_frames.h"
#include "tools/eval/scene_kind.h"
#include "tools/eval/stats.h"
#include "tools/eval/training_scenes.h"

namespace fovea::eval {
namespace {

// A segment found an object when their F reaches this.
constexpr double kFoundF = 0.5;
constexpr double kOverlayAlpha = 0.55;

// What one scene's run scored.
struct SceneRecord : SegmentFigures {
  std::string set, method, kind, name;
  double hit_ratio = 0.0;
  int off_object_points = 0;
  bool no_support = false;
  int table_hits = 0;
  double total_ms = 0.0;
};

// ObjectIdImage without the objects of fewer than `min_pixels` pixels.
cv::Mat ObjectIds(const cv::Mat& labels, int min_pixels) {
  cv::Mat ids = ObjectIdImage(labels);
  std::map<int, int> count;
  for (int v = 0; v < ids.rows; ++v) {
    const int* id = ids.ptr<int>(v);
    for (int u = 0; u < ids.cols; ++u) {
      if (id[u] > 0) ++count[id[u]];
    }
  }
  for (const auto& [id, n] : count) {
    if (n < min_pixels) ids.setTo(0, ids == id);
  }
  return ids;
}

int MinPixels(const cv::Mat& labels) {
  return std::max(1, static_cast<int>(kEvalMinObjectPixels * labels.total() /
                                      (640.0 * 480.0)));
}

void WriteOverlay(const std::string& dir, const std::string& name,
                  const RgbdFrame& frame, const std::vector<SeededMask>& masks,
                  const cv::Mat& labels) {
  std::filesystem::create_directories(dir);
  cv::Mat bgr;
  cv::cvtColor(frame.color, bgr, cv::COLOR_RGB2BGR);
  cv::Mat overlay = bgr.clone();
  for (size_t i = 0; i < masks.size(); ++i) {
    overlay.setTo(MaskColor(i), masks[i].mask);
  }
  cv::addWeighted(overlay, kOverlayAlpha, bgr, 1.0 - kOverlayAlpha, 0.0,
                  overlay);
  for (size_t i = 0; i < masks.size(); ++i) {
    cv::Mat edges;
    cv::Canny(masks[i].mask, edges, 1, 1);
    overlay.setTo(cv::Scalar(255, 255, 255), edges);
    cv::putText(overlay, std::to_string(i + 1), masks[i].seed,
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 2);
    cv::putText(overlay, std::to_string(i + 1), masks[i].seed,
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1);
  }
  cv::Mat right = bgr.clone();
  if (!labels.empty()) {
    cv::Mat objects;
    ObjectIdImage(labels).convertTo(objects, CV_8U, 20);
    cv::Mat edges;
    cv::Canny(objects, edges, 1, 1);
    right.setTo(cv::Scalar(0, 255, 0), edges);
  }
  cv::Mat both;
  cv::hconcat(overlay, right, both);
  cv::imwrite((std::filesystem::path(dir) / (name + ".png")).string(), both);
}

// The run's masks; NOT_FOUND (no support) gives none and marks the record.
absl::StatusOr<SceneRun> RunOrEmpty(const LabelledFrame& scene,
                                    const SceneRunOptions& run_options,
                                    SceneRecord& r) {
  absl::StatusOr<SceneRun> run = RunOnScene(scene, run_options);
  if (absl::IsNotFound(run.status())) {
    r.no_support = true;
    SceneRun empty;
    empty.segments = cv::Mat(scene.labels.size(), CV_32SC1, cv::Scalar(-1));
    return empty;
  }
  if (!run.ok()) return InScene(scene.name, run.status());
  return run;
}

// The run's attention points (Detect with the server's default options,
// which the segmentation runs with): HR over max(K, 10) points. No support:
// no points, HR 0.
void ScoreAttention(const LabelledFrame& scene,
                    const std::vector<AttentionPoint>& points, SceneRecord& r) {
  const OrganizedCloud cloud = BackProject(scene.frame);
  const DetectionScore score =
      ScoreAttentionPoints(points, scene.labels, cloud.xyz, kHitRatioAtMax);
  r.hit_ratio = score.hit_ratio;
  r.off_object_points = score.off_object_points;
}

struct SetContext {
  const ScorecardOptions* options;
  std::vector<SceneRecord>* records;
};

// `describe`, when given, names an object (by ObjectId) for --verbose's
// list of the objects no segment found.
absl::Status ScoreLabelledScene(
    const SetContext& ctx, const std::string& set, const std::string& kind,
    const LabelledFrame& scene, const SegmentModels& models,
    const std::function<std::string(int)>& describe = {}) {
  for (const SceneMethod method : ctx.options->methods) {
    SceneRecord r;
    r.set = set;
    r.method = std::string(SceneMethodName(method));
    r.kind = kind;
    r.name = scene.name;
    SceneRunOptions run_options;
    run_options.method = method;
    run_options.models = models;
    FOVEA_ASSIGN_OR_RETURN(SceneRun run, RunOrEmpty(scene, run_options, r));
    r.total_ms = run.total_ms;
    static_cast<SegmentFigures&>(r) = ScoreSegments(scene.labels, run.segments);
    ScoreAttention(scene, run.points, r);
    if (ctx.options->verbose) {
      std::fprintf(stderr,
                   "%-10s %-4s %-10s %-22s objects %2d found %2d masks/obj "
                   "%.2f false %d overlap F %.3f boundary F %.3f HR %.2f%s\n",
                   set.c_str(), r.method.c_str(), kind.c_str(),
                   scene.name.c_str(), r.objects, r.found,
                   r.objects_with_masks
                       ? 1.0 * r.object_masks / r.objects_with_masks
                       : 0.0,
                   r.false_objects, r.uois.overlap_f, r.uois.boundary_f,
                   r.hit_ratio, r.no_support ? " NO SUPPORT" : "");
      if (describe) {
        for (const int id : r.missed) {
          std::fprintf(stderr, "%-10s %-4s %-10s %-22s   missed: %s\n",
                       set.c_str(), r.method.c_str(), kind.c_str(),
                       scene.name.c_str(), describe(id).c_str());
        }
        for (const auto& [id, masks] : r.in_pieces) {
          std::fprintf(stderr, "%-10s %-4s %-10s %-22s   in %d masks: %s\n",
                       set.c_str(), r.method.c_str(), kind.c_str(),
                       scene.name.c_str(), masks, describe(id).c_str());
        }
      }
    }
    if (!ctx.options->out_dir.empty()) {
      WriteOverlay(absl::StrCat(ctx.options->out_dir, "/", set),
                   absl::StrCat(scene.name, "_", r.method), scene.frame,
                   run.masks, scene.labels);
    }
    ctx.records->push_back(std::move(r));
  }
  return absl::OkStatus();
}

bool Wants(const ScorecardOptions& o, const std::string& set) {
  return o.sets.empty() ||
         std::find(o.sets.begin(), o.sets.end(), set) != o.sets.end();
}

bool UsesMethod(const ScorecardOptions& o, SceneMethod m) {
  return std::find(o.methods.begin(), o.methods.end(), m) != o.methods.end();
}

// The OSD sets, leave-one-kind-out.
absl::Status RunOsdSets(const SetContext& ctx) {
  const ScorecardOptions& o = *ctx.options;
  const std::vector<std::string> variants = {"osd", "osd-rot90", "osd-rot180",
                                             "osd-half"};
  bool any = false;
  for (const std::string& v : variants) any = any || Wants(o, v);
  if (!any || o.osd_dir.empty()) return absl::OkStatus();
  FOVEA_ASSIGN_OR_RETURN(std::vector<LabelledFrame> scenes,
                         LoadScenes(o.osd_dir));
  std::vector<std::string> kinds, kind_of;
  for (const LabelledFrame& s : scenes) {
    kind_of.push_back(SceneKind(s.name));
    if (std::find(kinds.begin(), kinds.end(), kind_of.back()) == kinds.end())
      kinds.push_back(kind_of.back());
  }
  // Training examples of every scene and of the training piles, once.
  const IncrementalOptions inc_defaults;
  const SegmentOptions segment_defaults;
  std::vector<std::vector<SvmSample>> inc(scenes.size()), cos(scenes.size());
  std::vector<SvmSample> pile_inc;
  const bool uses_inc = UsesMethod(o, SceneMethod::kInc);
  const bool uses_cos = UsesMethod(o, SceneMethod::kCos);
  for (size_t i = 0; i < scenes.size(); ++i) {
    if (uses_inc) {
      absl::StatusOr<std::vector<SvmSample>> s =
          CollectIncSamples(scenes[i], static_cast<int>(i), inc_defaults.detect,
                            inc_defaults.inc);
      if (!s.ok()) return InScene(scenes[i].name, s.status());
      inc[i] = *std::move(s);
    }
    if (uses_cos) {
      absl::StatusOr<std::vector<SvmSample>> s =
          CollectCosSamples(scenes[i], static_cast<int>(i),
                            segment_defaults.detect, segment_defaults.cos);
      if (!s.ok()) return InScene(scenes[i].name, s.status());
      cos[i] = *std::move(s);
    }
  }
  if (uses_inc) {
    const std::vector<LabelledFrame> synthetic =
        SyntheticTrainingScenes(o.training_piles, o.training_stacked);
    for (size_t k = 0; k < synthetic.size(); ++k) {
      FOVEA_ASSIGN_OR_RETURN(
          std::vector<SvmSample> s,
          CollectIncSamples(synthetic[k], static_cast<int>(scenes.size() + k),
                            inc_defaults.detect, inc_defaults.inc));
      pile_inc.insert(pile_inc.end(), s.begin(), s.end());
    }
  }
  for (const std::string& held_out : kinds) {
    std::vector<SvmSample> inc_train = pile_inc, cos_train;
    std::vector<const LabelledFrame*> frames;
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (kind_of[i] == held_out) continue;
      inc_train.insert(inc_train.end(), inc[i].begin(), inc[i].end());
      cos_train.insert(cos_train.end(), cos[i].begin(), cos[i].end());
      frames.push_back(&scenes[i]);
    }
    std::optional<RbfSvm> inc_svm;
    std::optional<LinearSvm> cos_svm;
    std::optional<EbsModel> ebs;
    SegmentModels models;
    if (uses_inc) {
      FOVEA_ASSIGN_OR_RETURN(
          RbfSvm svm, TrainRbfSvm(inc_train, RelationFeatureNames(), "inc",
                                  RbfSvmTrainingOptions{}));
      inc_svm = std::move(svm);
      models.inc = &*inc_svm;
    }
    if (uses_cos) {
      FOVEA_ASSIGN_OR_RETURN(LinearSvm svm,
                             TrainLinearSvm(cos_train, CosFeatureNames(), "cos",
                                            LinearSvmTrainingOptions{}));
      cos_svm = std::move(svm);
      models.cos = &*cos_svm;
    }
    if (UsesMethod(o, SceneMethod::kEbs)) {
      FOVEA_ASSIGN_OR_RETURN(EbsModel m,
                             EbsModel::Train(frames, EbsTrainOptions{}));
      ebs = std::move(m);
      models.ebs = &*ebs;
    }
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (kind_of[i] != held_out) continue;
      if (Wants(o, "osd")) {
        FOVEA_RETURN_IF_ERROR(
            ScoreLabelledScene(ctx, "osd", held_out, scenes[i], models));
      }
      for (const int turns : {1, 2}) {
        const std::string set = absl::StrCat("osd-rot", 90 * turns);
        if (!Wants(o, set)) continue;
        FOVEA_RETURN_IF_ERROR(ScoreLabelledScene(
            ctx, set, held_out, RotateLabelledFrame(scenes[i], turns), models));
      }
      if (Wants(o, "osd-half")) {
        FOVEA_RETURN_IF_ERROR(ScoreLabelledScene(
            ctx, "osd-half", held_out, HalveLabelledFrame(scenes[i]), models));
      }
    }
  }
  return absl::OkStatus();
}

absl::Status RunSyntheticSets(const SetContext& ctx) {
  const ScorecardOptions& o = *ctx.options;
  const SegmentModels models = o.models->View();
  if (Wants(o, "piles")) {
    for (int k = 0; k < o.piles; ++k) {
      const synth::SynthScene pile = synth::GeneratePile(1 + k);
      FOVEA_RETURN_IF_ERROR(
          ScoreLabelledScene(ctx, "piles", "pile", pile.frame, models));
    }
  }
  const synth::RoomSensor sensors[] = {synth::RoomSensor::kKinectV1,
                                       synth::RoomSensor::kActiveStereo};
  // The stacked piles as generated, with OSD's crop (the table seen only in
  // front of the pile's middle, as OSD's Kinect frames were cut: the Kinect
  // and the active stereo), and every kind (drills, bananas, pens, small
  // parts, towers) seen from above; each at its sensor's usual resolution.
  const synth::RoomSensor all_sensors[] = {synth::RoomSensor::kKinectV1,
                                           synth::RoomSensor::kActiveStereo,
                                           synth::RoomSensor::kTimeOfFlight};
  struct StackedSet {
    std::string name;
    synth::StackedPile (*generate)(uint64_t, synth::RoomSensor);
    absl::Span<const synth::RoomSensor> sensors;
  };
  const StackedSet stacked_sets[] = {
      {"stacked", &synth::GenerateStackedPile, all_sensors},
      {"stacked-crop", &synth::GenerateCroppedPile, sensors},
      {"stacked-above",
       [](uint64_t seed, synth::RoomSensor sensor) {
         return synth::GenerateStackedPile(seed, sensor,
                                           synth::AbovePileOptions(sensor));
       },
       all_sensors}};
  for (const StackedSet& stacked_set : stacked_sets) {
    const std::string& set = stacked_set.name;
    if (!Wants(o, set)) continue;
    for (const synth::RoomSensor sensor : stacked_set.sensors) {
      for (int k = 0; k < o.stacked; ++k) {
        const synth::StackedPile pile = stacked_set.generate(1 + k, sensor);
        // Object k has label 10 (k + 2), ObjectId k + 2.
        const auto describe = [&pile](int id) {
          const int k = id - 2;
          if (k < 0 || k >= static_cast<int>(pile.kinds.size())) {
            return absl::StrCat("object ", id);
          }
          const int on = pile.rests_on[k];
          return std::string(synth::StackedKindName(pile.kinds[k])) + " on " +
                 (on < 0 ? std::string("the table")
                         : std::string(synth::StackedKindName(pile.kinds[on])));
        };
        FOVEA_RETURN_IF_ERROR(ScoreLabelledScene(
            ctx, set, std::string(synth::RoomSensorName(sensor)),
            pile.scene.frame, models, describe));
      }
    }
  }
  if (Wants(o, "rooms")) {
    for (const synth::RoomSensor sensor : sensors) {
      synth::RoomOptions room;
      room.sensor = sensor;
      for (int k = 0; k < o.rooms; ++k) {
        const synth::SynthScene scene = synth::GenerateRoom(1 + k, room);
        FOVEA_RETURN_IF_ERROR(ScoreLabelledScene(
            ctx, "rooms", std::string(synth::RoomSensorName(sensor)),
            scene.frame, models));
      }
    }
  }
  return absl::OkStatus();
}

bool Covered(const cv::Mat& segments, cv::Point p) {
  return p.x >= 0 && p.y >= 0 && p.x < segments.cols && p.y < segments.rows &&
         segments.at<int>(p) >= 0;
}

absl::Status RunRealSenseSet(const SetContext& ctx) {
  const ScorecardOptions& o = *ctx.options;
  if (!Wants(o, "realsense")) return absl::OkStatus();
  const std::string dir = RealSenseDir(o.realsense_dir);
  if (dir.empty()) return absl::OkStatus();
  for (const RealSenseFrame& f : LoadRealSenseFrames(dir)) {
    for (const SceneMethod method : o.methods) {
      SceneRecord r;
      r.set = "realsense";
      r.method = std::string(SceneMethodName(method));
      r.kind = "office";
      r.name = f.name;
      SceneRunOptions run_options;
      run_options.method = method;
      run_options.models = o.models->View();
      LabelledFrame scene;
      scene.name = f.name;
      scene.frame.color = f.frame.color;
      scene.frame.depth = f.frame.depth;
      scene.frame.intrinsics = f.frame.intrinsics;
      scene.labels = cv::Mat::zeros(f.frame.depth.size(), CV_32SC1);
      FOVEA_ASSIGN_OR_RETURN(SceneRun run, RunOrEmpty(scene, run_options, r));
      r.total_ms = run.total_ms;
      r.objects = static_cast<int>(f.objects.size());
      std::vector<bool> off(run.masks.size(), false);
      for (const cv::Point& p : f.objects) r.found += Covered(run.segments, p);
      for (const auto* list : {&f.table, &f.off_table}) {
        for (const cv::Point& p : *list) {
          if (!Covered(run.segments, p)) continue;
          ++r.table_hits;
          off[run.segments.at<int>(p)] = true;
        }
      }
      for (size_t i = 0; i < run.masks.size(); ++i) {
        if (off[i]) {
          ++r.false_objects;
        } else {
          ++r.object_masks;
        }
      }
      r.objects_with_masks = r.objects;
      if (o.verbose) {
        std::fprintf(stderr,
                     "realsense %-4s %-4s objects %2d found %2d masks %zu "
                     "table/off-table hits %d\n",
                     r.method.c_str(), f.name.c_str(), r.objects, r.found,
                     run.masks.size(), r.table_hits);
      }
      if (!o.out_dir.empty()) {
        WriteOverlay(absl::StrCat(o.out_dir, "/realsense"),
                     absl::StrCat(f.name, "_", r.method), scene.frame,
                     run.masks, cv::Mat());
      }
      ctx.records->push_back(std::move(r));
    }
  }
  return absl::OkStatus();
}

ScorecardRow Summarize(const std::vector<const SceneRecord*>& records) {
  ScorecardRow row;
  int objects = 0, found = 0, masks = 0, with_masks = 0;
  std::vector<double> ms;
  for (const SceneRecord* r : records) {
    ++row.scenes;
    row.overlap_p += r->uois.overlap_p;
    row.overlap_r += r->uois.overlap_r;
    row.overlap_f += r->uois.overlap_f;
    row.boundary_f += r->uois.boundary_f;
    row.objects_075 += r->uois.objects_075;
    row.false_objects += r->false_objects;
    row.hit_ratio += r->hit_ratio;
    row.off_object_points += r->off_object_points;
    row.no_support += r->no_support;
    row.table_hits += r->table_hits;
    objects += r->objects;
    found += r->found;
    masks += r->object_masks;
    with_masks += r->objects_with_masks;
    ms.push_back(r->total_ms);
  }
  const double n = std::max(row.scenes, 1);
  for (double* x : {&row.overlap_p, &row.overlap_r, &row.overlap_f,
                    &row.boundary_f, &row.objects_075, &row.false_objects,
                    &row.hit_ratio, &row.off_object_points}) {
    *x /= n;
  }
  row.objects = objects;
  row.object_recall = objects > 0 ? 1.0 * found / objects : 0.0;
  row.masks_per_object = with_masks > 0 ? 1.0 * masks / with_masks : 0.0;
  row.total_ms_median = Median(ms);
  return row;
}

}  // namespace

SegmentFigures ScoreSegments(const cv::Mat& labels, const cv::Mat& segments) {
  SegmentFigures r;
  const int min_pixels = MinPixels(labels);
  const cv::Mat ids = ObjectIds(labels, min_pixels);
  r.uois = ScoreUois(ids, segments, min_pixels);
  std::map<int, int> object_size;
  std::map<int, int> segment_size;
  std::map<int, int> segment_other;            // labelled pixels on no object
  std::map<std::pair<int, int>, int> overlap;  // (segment, object)
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    const int* id = ids.ptr<int>(v);
    const int* s = segments.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (id[u] > 0) ++object_size[id[u]];
      if (s[u] < 0) continue;
      ++segment_size[s[u]];
      if (id[u] > 0) {
        ++overlap[{s[u], id[u]}];
      } else if (l[u] != 0) {
        ++segment_other[s[u]];
      }
    }
  }
  r.objects = static_cast<int>(object_size.size());
  std::map<int, int> masks_on;  // object -> segments lying mostly on it
  std::map<int, std::pair<int, int>> owner;  // segment -> (object, pixels)
  for (const auto& [key, n] : overlap) {
    auto& best = owner[key.first];
    if (n > best.second) best = {key.second, n};
  }
  for (const auto& [segment, size] : segment_size) {
    const auto it = owner.find(segment);
    const int on_object = it == owner.end() ? 0 : it->second.second;
    const int other = segment_other.count(segment) ? segment_other[segment] : 0;
    if (on_object == 0 && other == 0) continue;  // on no labelled pixel
    if (on_object >= other) {
      ++masks_on[it->second.first];
    } else {
      ++r.false_objects;
    }
  }
  for (const auto& [object, n] : masks_on) {
    r.object_masks += n;
    ++r.objects_with_masks;
    if (n > 1) r.in_pieces.emplace_back(object, n);
  }
  for (const auto& [object, size] : object_size) {
    bool found = false;
    for (const auto& [segment, ssize] : segment_size) {
      const auto it = overlap.find({segment, object});
      if (it == overlap.end()) continue;
      if (2.0 * it->second / (size + ssize) >= kFoundF) {
        found = true;
        break;
      }
    }
    if (found) {
      ++r.found;
    } else {
      r.missed.push_back(object);
    }
  }
  return r;
}

absl::StatusOr<std::vector<ScorecardRow>> RunScorecard(
    const ScorecardOptions& options) {
  if (options.models == nullptr) {
    return absl::InvalidArgumentError("scorecard: models are required");
  }
  if (options.methods.empty()) {
    return absl::InvalidArgumentError("scorecard: methods: none given");
  }
  std::vector<SceneRecord> records;
  const SetContext ctx{&options, &records};
  FOVEA_RETURN_IF_ERROR(RunOsdSets(ctx));
  FOVEA_RETURN_IF_ERROR(RunSyntheticSets(ctx));
  FOVEA_RETURN_IF_ERROR(RunRealSenseSet(ctx));

  // Rows in order of first appearance: each (set, method)'s kinds, then
  // its "all".
  std::vector<ScorecardRow> rows;
  std::vector<std::pair<std::string, std::string>> groups;
  for (const SceneRecord& r : records) {
    const std::pair<std::string, std::string> g{r.set, r.method};
    if (std::find(groups.begin(), groups.end(), g) == groups.end())
      groups.push_back(g);
  }
  for (const auto& [set, method] : groups) {
    std::vector<std::string> kinds;
    for (const SceneRecord& r : records) {
      if (r.set == set && r.method == method &&
          std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) {
        kinds.push_back(r.kind);
      }
    }
    if (kinds.size() > 1) kinds.push_back("all");
    for (const std::string& kind : kinds) {
      std::vector<const SceneRecord*> chosen;
      for (const SceneRecord& r : records) {
        if (r.set == set && r.method == method &&
            (kind == "all" || r.kind == kind)) {
          chosen.push_back(&r);
        }
      }
      ScorecardRow row = Summarize(chosen);
      row.set = set;
      row.method = method;
      row.kind = kind;
      row.evaluation =
          set.rfind("osd", 0) == 0 ? "leave-one-kind-out" : "held-out";
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

}  // namespace fovea::eval
