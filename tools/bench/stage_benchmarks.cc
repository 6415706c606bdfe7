#include "tools/bench/stage_benchmarks.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/baseline/scene_segmenters.h"
#include "core/frame/dropout_fill.h"
#include "core/frame/frame_decode.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/surface_edges.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/pipeline/saliency_registry.h"
#include "core/pipeline/segment.h"
#include "core/saliency/ph.h"
#include "core/saliency/rso.h"
#include "core/saliency/sh.h"
#include "core/saliency/sym3d.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "core/segmentation/ebs.h"
#include "core/segmentation/planar_patches.h"
#include "core/segmentation/surface_model.h"
#include "tools/bench/object_geometry_benchmark.h"

namespace fovea::bench {
namespace {

// Rough per-frame cost of each case on one core, milliseconds; only sizes
// the number of passes per repetition (SweepIterations).
constexpr double kDecodeRawMs = 2.0;
constexpr double kDecodePngMs = 12.0;
constexpr double kBackProjectMs = 1.0;
constexpr double kDropoutFillMs = 2.0;
constexpr double kNormalsMs = 8.0;
constexpr double kSupportPlaneMs = 5.0;
constexpr double kFramePrepMs = 15.0;
constexpr double kSaliencyMs = 3.0;
constexpr double kMsrMs = 2.0;
constexpr double kSurfaceEdgesMs = 3.0;
constexpr double kPlanarPatchesMs = 15.0;
constexpr double kSurfaceModelMs = 2.0;
constexpr double kSym3dLevel0Ms = 40.0;
constexpr double kEbsEdgeProbabilityMs = 12.0;
constexpr double kEbsContourMs = 4.0;
constexpr double kPeerEuclideanMs = 40.0;
constexpr double kPeerLccpMs = 40.0;

// The stages before saliency, as RunDetect runs them, from the raw wire
// frame: decode, back-projection and normals, support plane, table scene.
absl::Status PrepareFrame(const BenchScene& scene,
                          const DetectOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(RgbdFrame frame,
                         DecodeFrame(scene.raw_wire, BenchFrameLimits()));
  FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud,
                         BuildOrganizedCloud(frame, options.normals));
  FOVEA_ASSIGN_OR_RETURN(SupportPlane plane,
                         FindSupportPlane(cloud, options.support_plane));
  TableScene table = PrepareTableScene(cloud, plane, options.table_scene);
  benchmark::DoNotOptimize(table.candidate_count);
  return absl::OkStatus();
}

void RegisterFramePrepCases(const SceneList* scenes, const std::string& set,
                            const std::string& suffix,
                            const SweepOptions& sweep) {
  const DetectOptions defaults;
  Register("BM_DecodeRaw" + suffix, scenes, set, sweep, kDecodeRawMs,
           [](const BenchScene& scene) {
             absl::StatusOr<RgbdFrame> frame =
                 DecodeFrame(scene.raw_wire, BenchFrameLimits());
             benchmark::DoNotOptimize(frame);
             return frame.status();
           });
  Register("BM_DecodePng" + suffix, scenes, set, sweep, kDecodePngMs,
           [](const BenchScene& scene) {
             absl::StatusOr<RgbdFrame> frame =
                 DecodeFrame(scene.png_wire, BenchFrameLimits());
             benchmark::DoNotOptimize(frame);
             return frame.status();
           });
  Register("BM_BackProject" + suffix, scenes, set, sweep, kBackProjectMs,
           [](const BenchScene& scene) {
             OrganizedCloud cloud = BackProject(scene.frame);
             benchmark::DoNotOptimize(cloud.xyz.data);
             return absl::OkStatus();
           });
  Register("BM_DropoutFill" + suffix, scenes, set, sweep, kDropoutFillMs,
           [options = defaults.dropout_fill](const BenchScene& scene) {
             absl::StatusOr<FilledDepth> filled = FillSpeckledDropout(
                 options,
                 SensorModelFor(SensorKind::kGeneric, scene.frame.intrinsics),
                 scene.frame.color, scene.frame.depth);
             if (!filled.ok()) return filled.status();
             benchmark::DoNotOptimize(filled->depth.data);
             return absl::OkStatus();
           });
  Register("BM_Normals" + suffix, scenes, set, sweep, kNormalsMs,
           [options = defaults.normals](const BenchScene& scene) {
             // Shares the prepared points (read only); the normals are
             // allocated afresh, as in BuildOrganizedCloud.
             OrganizedCloud cloud;
             cloud.xyz = scene.cloud.xyz;
             cloud.color = scene.cloud.color;
             cloud.intrinsics = scene.cloud.intrinsics;
             EstimateNormals(options, cloud);
             benchmark::DoNotOptimize(cloud.normals.data);
             return absl::OkStatus();
           });
  Register("BM_SupportPlane" + suffix, scenes, set, sweep, kSupportPlaneMs,
           [defaults](const BenchScene& scene) {
             FOVEA_ASSIGN_OR_RETURN(
                 SupportPlane plane,
                 FindSupportPlane(scene.cloud, defaults.support_plane));
             TableScene table =
                 PrepareTableScene(scene.cloud, plane, defaults.table_scene);
             benchmark::DoNotOptimize(table.candidate_count);
             return absl::OkStatus();
           });
  Register("BM_FramePrep" + suffix, scenes, set, sweep, kFramePrepMs,
           [defaults](const BenchScene& scene) {
             return PrepareFrame(scene, defaults);
           });
}

void RegisterSaliencyCases(const SceneList* scenes, const std::string& set,
                           const std::string& suffix,
                           const SweepOptions& sweep) {
  const DetectOptions defaults;
  Register("BM_SaliencyPh" + suffix, scenes, set, sweep, kSaliencyMs,
           [options = defaults.ph](const BenchScene& scene) {
             absl::StatusOr<cv::Mat> map =
                 ComputePhSaliency(scene.table, options);
             benchmark::DoNotOptimize(map);
             return map.status();
           });
  Register("BM_SaliencySh" + suffix, scenes, set, sweep, kSaliencyMs,
           [options = defaults.sh](const BenchScene& scene) {
             absl::StatusOr<cv::Mat> map = ComputeShSaliency(
                 scene.cloud, scene.plane, scene.table, options);
             benchmark::DoNotOptimize(map);
             return map.status();
           });
  // SYM3D on the full-resolution level: the SIMPLE pyramid's most costly
  // level (level l has 4^-l of its pixels).
  Register("BM_SaliencySym3d/level0" + suffix, scenes, set, sweep,
           kSym3dLevel0Ms, [options = defaults.sym3d](const BenchScene& scene) {
             absl::StatusOr<cv::Mat> map =
                 ComputeSym3dSaliency(scene.cloud, scene.table, options);
             benchmark::DoNotOptimize(map);
             return map.status();
           });
  // Planar patches (thesis section 3.2.2), the first step of every
  // segmentation, as COS and INC call it: on the table scene's region, the
  // support's inliers taken as they are.
  Register("BM_PlanarPatches" + suffix, scenes, set, sweep, kPlanarPatchesMs,
           [](const BenchScene& scene) {
             absl::StatusOr<PlanarPatches> patches = FindPlanarPatches(
                 scene.cloud, scene.table.region, {}, scene.plane.inliers);
             benchmark::DoNotOptimize(patches);
             return patches.status();
           });
  Register("BM_SurfaceEdges" + suffix, scenes, set, sweep, kSurfaceEdgesMs,
           [options = defaults.surface_edges](const BenchScene& scene) {
             cv::Mat edges = FindSurfaceEdges(scene.cloud, options);
             benchmark::DoNotOptimize(edges);
             return absl::OkStatus();
           });
  // EBS (thesis section 3.2.3): the three edge maps and their naive-Bayes
  // fusion on the whole frame, then one fixation's polar contour.
  Register("BM_EbsEdgeProbability" + suffix, scenes, set, sweep,
           kEbsEdgeProbabilityMs, [](const BenchScene& scene) {
             const absl::StatusOr<EbsModel>& model = BenchEbsModel();
             if (!model.ok()) return model.status();
             cv::Mat p = model->EdgeProbability(
                 ComputeEdgeMaps(scene.cloud, model->edge_map_options()));
             benchmark::DoNotOptimize(p.data);
             return absl::OkStatus();
           });
  Register("BM_EbsContour" + suffix, scenes, set, sweep, kEbsContourMs,
           [](const BenchScene& scene) {
             absl::StatusOr<cv::Mat> mask = SegmentAtFixation(
                 scene.edge_probability, scene.fixation, PolarContourOptions{});
             benchmark::DoNotOptimize(mask);
             return mask.status();
           });
  Register("BM_SaliencyRso" + suffix, scenes, set, sweep, kSaliencyMs,
           [options = defaults.rso](const BenchScene& scene) {
             absl::StatusOr<cv::Mat> map = ComputeRsoSaliency(
                 scene.cloud, scene.plane, scene.table, options);
             benchmark::DoNotOptimize(map);
             return map.status();
           });
  for (const ExtractionKind kind :
       {ExtractionKind::kMsr, ExtractionKind::kWta, ExtractionKind::kTj}) {
    DetectOptions options = defaults;
    options.extraction = kind;
    std::string name(ExtractionName(kind));
    name[0] = static_cast<char>(std::toupper(name[0]));
    Register(absl::StrCat("BM_", name, suffix), scenes, set, sweep, kMsrMs,
             [options](const BenchScene& scene) {
               absl::StatusOr<std::vector<AttentionPoint>> points =
                   ExtractAttentionPoints(scene.rso_map, options);
               benchmark::DoNotOptimize(points);
               return points.status();
             });
  }
}

// The points of each planar patch of `cloud`, in raster order, as
// incremental segmentation would hand them to FitSurface.
absl::StatusOr<std::vector<std::vector<Eigen::Vector3f>>> PatchPoints(
    const OrganizedCloud& cloud, const PlanarPatchOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(PlanarPatches patches,
                         FindPlanarPatches(cloud, {}, options));
  std::vector<std::vector<Eigen::Vector3f>> points(patches.patches.size());
  for (int v = 0; v < cloud.height(); ++v) {
    for (int u = 0; u < cloud.width(); ++u) {
      const int id = patches.labels.at<int>(v, u);
      if (id < 0) continue;
      const cv::Vec3f& p = cloud.xyz.at<cv::Vec3f>(v, u);
      points[id].emplace_back(p[0], p[1], p[2]);
    }
  }
  return points;
}

// Surface models (thesis section 3.3): FitSurface (plane and B-spline by
// MDL) on every planar patch of the frame. The patches are found and their
// points gathered before the timed loop; counters give the mean patches
// per frame and the share that came out as B-splines. "BM_SurfaceModel"
// takes the default patches (about 30 per OSD frame); "BM_SurfaceModel/
// fine" patches grown with tighter thresholds (half the distance, 10
// degrees, 15-point minimum): about 200 per OSD frame, the many small
// patches of a cluttered one (on the synthetic frames most points fail the
// tight thresholds and are left out, so there are fewer).
void RegisterSurfaceModelCases(const SceneList* scenes, const std::string& set,
                               const std::string& suffix,
                               const SweepOptions& sweep) {
  PlanarPatchOptions fine;
  fine.max_plane_distance = 0.002f;
  fine.distance_per_m2 = 0.00075f;
  fine.max_normal_angle_deg = 10.0f;
  fine.min_points = 15;
  for (const auto& [name, patch_options] :
       {std::pair<std::string, PlanarPatchOptions>{"", PlanarPatchOptions{}},
        {"/fine", fine}}) {
    benchmark::RegisterBenchmark(
        ("BM_SurfaceModel" + name + suffix).c_str(),
        [scenes, set, patch_options = patch_options](benchmark::State& state) {
          const SurfaceModelOptions options;
          std::unordered_map<const BenchScene*,
                             std::vector<std::vector<Eigen::Vector3f>>>
              patches;
          double patch_count = 0.0, splines = 0.0;
          for (const auto& scene : *scenes) {
            absl::StatusOr<std::vector<std::vector<Eigen::Vector3f>>> points =
                PatchPoints(scene->cloud, patch_options);
            if (!points.ok()) {
              state.SkipWithError(points.status().ToString().c_str());
              return;
            }
            for (const auto& patch : *points) {
              absl::StatusOr<SurfaceModel> model = FitSurface(patch, options);
              if (model.ok() && model->kind == SurfaceKind::kBSpline) {
                ++splines;
              }
            }
            patch_count += static_cast<double>(points->size());
            patches.emplace(scene.get(), *std::move(points));
          }
          SweepScenes(state, *scenes, set, [&](const BenchScene& scene) {
            for (const auto& points : patches.at(&scene)) {
              FOVEA_ASSIGN_OR_RETURN(SurfaceModel model,
                                     FitSurface(points, options));
              benchmark::DoNotOptimize(model.description_length);
            }
            return absl::OkStatus();
          });
          state.counters["patches"] = patch_count / scenes->size();
          state.counters["bspline_share"] =
              patch_count > 0.0 ? splines / patch_count : 0.0;
        })
        ->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                     kSurfaceModelMs))
        ->Unit(benchmark::kMillisecond);
  }
}

// Segment in-process with the default options: "first" stops after the
// first object (the time a robot waits for it), "all" cuts one object per
// attention point.
void RegisterSegmentCases(const SceneList* scenes, const std::string& set,
                          const std::string& suffix,
                          const SweepOptions& sweep) {
  for (const SegmentMethod method :
       {SegmentMethod::kCos, SegmentMethod::kEbs}) {
    for (const bool first : {true, false}) {
      SegmentOptions options;
      options.method = method;
      options.max_objects = first ? 1 : 0;
      Register(absl::StrCat("BM_Segment/", AbslView(SegmentMethodName(method)),
                            first ? "/first" : "/all", suffix),
               scenes, set, sweep, kSegmentMs,
               [options](const BenchScene& scene) {
                 const absl::StatusOr<LoadedModels>& models = BenchModels();
                 if (!models.ok()) return models.status();
                 absl::StatusOr<SegmentSummary> summary = RunSegment(
                     scene.frame, options, models->View(), SegmentSinks{});
                 benchmark::DoNotOptimize(summary);
                 return summary.status();
               });
    }
  }
}

// The whole-scene PCL peers of core/baseline/scene_segmenters.h, from the
// organized cloud with normals (what our own segmentation starts from too):
// support plane by organized multi-plane segmentation, then Euclidean
// clustering or supervoxels + LCCP.
void RegisterPeerCases(const SceneList* scenes, const std::string& set,
                       const std::string& suffix, const SweepOptions& sweep) {
  Register("BM_PeerEuclidean" + suffix, scenes, set, sweep, kPeerEuclideanMs,
           [](const BenchScene& scene) {
             absl::StatusOr<SceneSegmentation> segmentation =
                 SegmentSceneEuclidean(scene.cloud, EuclideanSceneOptions{});
             benchmark::DoNotOptimize(segmentation);
             return segmentation.status();
           });
  Register("BM_PeerLccp" + suffix, scenes, set, sweep, kPeerLccpMs,
           [](const BenchScene& scene) {
             absl::StatusOr<SceneSegmentation> segmentation =
                 SegmentSceneLccp(scene.cloud, LccpSceneOptions{});
             benchmark::DoNotOptimize(segmentation);
             return segmentation.status();
           });
  // The same from the raw wire frame (decode, cloud and normals timed),
  // as SegmentIncremental starts: BM_SegmentIncrementalGrpc/all's peer.
  Register("BM_PeerLccpRaw" + suffix, scenes, set, sweep, kPeerLccpMs,
           [](const BenchScene& scene) -> absl::Status {
             FOVEA_ASSIGN_OR_RETURN(
                 RgbdFrame frame,
                 DecodeFrame(scene.raw_wire, BenchFrameLimits()));
             FOVEA_ASSIGN_OR_RETURN(
                 const OrganizedCloud cloud,
                 BuildOrganizedCloud(frame, DetectOptions{}.normals));
             absl::StatusOr<SceneSegmentation> segmentation =
                 SegmentSceneLccp(cloud, LccpSceneOptions{});
             benchmark::DoNotOptimize(segmentation);
             return segmentation.status();
           });
}

void RegisterDetectCases(const SceneList* scenes, const std::string& set,
                         const std::string& suffix, const SweepOptions& sweep) {
  // What a request without options gets.
  Register("BM_Detect/default" + suffix, scenes, set, sweep, kDetectMs,
           [](const BenchScene& scene) {
             absl::StatusOr<DetectResult> result =
                 RunDetect(scene.frame, DetectOptions{});
             benchmark::DoNotOptimize(result);
             return result.status();
           });
  // The same from the wire frame (raw rgb8 + 16UC1, decoded in the
  // timing): what BM_DetectGrpc/default does in the server, so the pair's
  // ratio is the service's own cost.
  Register("BM_DetectRaw/default" + suffix, scenes, set, sweep, kDetectMs,
           [](const BenchScene& scene) {
             absl::StatusOr<RgbdFrame> frame =
                 DecodeFrame(scene.raw_wire, BenchFrameLimits());
             if (!frame.ok()) return frame.status();
             absl::StatusOr<DetectResult> result =
                 RunDetect(*frame, DetectOptions{});
             benchmark::DoNotOptimize(result);
             return result.status();
           });
  for (const std::string_view channels : kDetectChannelSets) {
    const absl::StatusOr<std::vector<SaliencyOp>> ops =
        ParseSaliencyOps(channels);
    // The foundation's configuration (one level, MSR, the thesis's master
    // map), so that these rows stay comparable across changes of defaults.
    DetectOptions options;
    options.pyramid = PyramidKind::kNone;
    options.extraction = ExtractionKind::kMsr;
    options.split_at_surface_edges = false;
    options.channels.clear();
    for (const SaliencyOp op : ops.value()) {
      options.channels.push_back({op, 1.0f});
    }
    Register(absl::StrCat("BM_Detect/", AbslView(channels), suffix), scenes,
             set, sweep, kDetectMs, [options](const BenchScene& scene) {
               absl::StatusOr<DetectResult> result =
                   RunDetect(scene.frame, options);
               benchmark::DoNotOptimize(result);
               return result.status();
             });
  }
}

// The attention strategies of chapter 2 whose times are reported:
// SYM3D with T-junctions on one level and on both pyramids, and each colour
// operator with MSR.
struct AttentionCase {
  std::string_view name;
  SaliencyOp op;
  PyramidKind pyramid;
  ExtractionKind extraction;
};
// Each runs with the defaults of DetectOptions otherwise (surface edges
// split the master map).
constexpr AttentionCase kAttentionCases[] = {
    {"sym3d/none/msr", SaliencyOp::kSym3d, PyramidKind::kNone,
     ExtractionKind::kMsr},
    {"sym3d/none/tj", SaliencyOp::kSym3d, PyramidKind::kNone,
     ExtractionKind::kTj},
    {"sym3d/itti/tj", SaliencyOp::kSym3d, PyramidKind::kItti,
     ExtractionKind::kTj},
    {"sym3d/simple/tj", SaliencyOp::kSym3d, PyramidKind::kSimple,
     ExtractionKind::kTj},
    {"itti/none/msr", SaliencyOp::kItti, PyramidKind::kNone,
     ExtractionKind::kMsr},
    {"harel/none/msr", SaliencyOp::kHarel, PyramidKind::kNone,
     ExtractionKind::kMsr},
    {"hou/none/msr", SaliencyOp::kHou, PyramidKind::kNone,
     ExtractionKind::kMsr},
    {"kootstra/none/msr", SaliencyOp::kKootstra, PyramidKind::kNone,
     ExtractionKind::kMsr},
};

void RegisterAttentionCases(const SceneList* scenes, const std::string& set,
                            const std::string& suffix,
                            const SweepOptions& sweep) {
  for (const AttentionCase& c : kAttentionCases) {
    DetectOptions options;
    options.channels = {{c.op, 1.0f}};
    options.pyramid = c.pyramid;
    options.extraction = c.extraction;
    Register(absl::StrCat("BM_DetectAttention/", AbslView(c.name), suffix),
             scenes, set, sweep, kDetectMs, [options](const BenchScene& scene) {
               absl::StatusOr<DetectResult> result =
                   RunDetect(scene.frame, options);
               benchmark::DoNotOptimize(result);
               return result.status();
             });
  }
  // Every operator of the registry alone (one level, MSR; the cues'
  // defaults), so that a new row gets its benchmark.
  for (const SaliencyOperator& row : SaliencyOperators()) {
    DetectOptions options;
    options.channels = {{row.op, 1.0f}};
    options.pyramid = PyramidKind::kNone;
    options.extraction = ExtractionKind::kMsr;
    Register(absl::StrCat("BM_Operator/", AbslView(row.name), suffix), scenes,
             set, sweep, kDetectMs, [options](const BenchScene& scene) {
               absl::StatusOr<DetectResult> result =
                   RunDetect(scene.frame, options);
               benchmark::DoNotOptimize(result);
               return result.status();
             });
  }
}

}  // namespace

void Register(const std::string& name, const SceneList* scenes,
              const std::string& set_name, const SweepOptions& sweep,
              double expected_ms, SceneBody body) {
  benchmark::RegisterBenchmark(
      name.c_str(),
      [scenes, set_name, body = std::move(body)](benchmark::State& state) {
        SweepScenes(state, *scenes, set_name, body);
      })
      ->Iterations(
          SweepIterations(sweep, static_cast<int>(scenes->size()), expected_ms))
      ->Unit(benchmark::kMillisecond);
}

const absl::StatusOr<LoadedModels>& BenchModels() {
  static const auto* models =
      new absl::StatusOr<LoadedModels>(LoadModels(FOVEA_BENCH_MODELS_DIR));
  return *models;
}

int64_t SweepIterations(const SweepOptions& sweep, int scene_count,
                        double expected_ms) {
  const double pass_seconds = scene_count * expected_ms * 1e-3;
  const int passes =
      sweep.passes > 0
          ? sweep.passes
          : std::max(1, static_cast<int>(std::ceil(
                            sweep.target_repetition_seconds / pass_seconds)));
  return static_cast<int64_t>(passes) * scene_count;
}

void SweepScenes(benchmark::State& state, const SceneList& scenes,
                 std::string_view set_name, const SceneBody& body) {
  size_t next = 0;
  for (auto _ : state) {
    const absl::Status status = body(*scenes[next]);
    if (!status.ok()) {
      state.SkipWithError(
          absl::StrCat(scenes[next]->name, ": ", status.ToString()).c_str());
      break;
    }
    if (++next == scenes.size()) next = 0;
  }
  state.SetLabel(
      absl::StrCat(scenes.size(), " ", AbslView(set_name), " frames"));
}

void RegisterStageBenchmarks(const SceneList* scenes,
                             const std::string& set_name,
                             const std::string& suffix,
                             const SweepOptions& sweep) {
  if (scenes->empty()) return;
  RegisterFramePrepCases(scenes, set_name, suffix, sweep);
  RegisterSaliencyCases(scenes, set_name, suffix, sweep);
  RegisterSurfaceModelCases(scenes, set_name, suffix, sweep);
  RegisterDetectCases(scenes, set_name, suffix, sweep);
  RegisterSegmentCases(scenes, set_name, suffix, sweep);
  RegisterObjectGeometryBenchmark(scenes, set_name, suffix, sweep);
  RegisterPeerCases(scenes, set_name, suffix, sweep);
  RegisterAttentionCases(scenes, set_name, suffix, sweep);
}

}  // namespace fovea::bench
