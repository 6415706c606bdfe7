#ifndef FOVEA_CORE_PIPELINE_DETECT_H_
#define FOVEA_CORE_PIPELINE_DETECT_H_

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/attention/attention_point.h"
#include "core/attention/msr.h"
#include "core/attention/tj.h"
#include "core/attention/wta.h"
#include "core/base/interrupt.h"
#include "core/base/name_table.h"
#include "core/base/stage_clock.h"
#include "core/frame/dropout_fill.h"
#include "core/frame/frame_scale.h"
#include "core/frame/hole_filling.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/rgbd_frame.h"
#include "core/frame/sensor_model.h"
#include "core/frame/surface_edges.h"
#include "core/pyramid/cloud_pyramid.h"
#include "core/pyramid/feature_pyramid.h"
#include "core/pyramid/normalization.h"
#include "core/saliency/harel.h"
#include "core/saliency/hou.h"
#include "core/saliency/itti.h"
#include "core/saliency/kootstra.h"
#include "core/saliency/ph.h"
#include "core/saliency/rso.h"
#include "core/saliency/sh.h"
#include "core/saliency/sym3d.h"
#include "core/saliency/top_down.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "core/scene/workspace.h"

namespace fovea {

// Saliency channels. Names (SaliencyOpName) are the command-line and
// metric names.
enum class SaliencyOp {
  kPh,
  kSh,
  kRso,
  kSym3d,
  kItti,
  kHarel,
  kHou,
  kKootstra,
  kTargetColor,
  kLocationPrior,
};
enum class PyramidKind { kNone, kSimple, kItti };
enum class LevelCombination { kSum, kMax };
enum class NormalizationKind { kLin, kNms, kNlm };
enum class FusionKind { kSum, kMax };
enum class ExtractionKind { kMsr, kWta, kTj };

// The one table of attention-point extractions, read like the saliency
// registry (saliency_registry.h): the wire value is the Extraction value
// whose name is the row's name in upper case. Adding one: its files in
// core/attention/ and their test, an ExtractionKind value, one row in
// option_names.cc, one Extraction value in detect.proto.
struct DetectOptions;
struct AttentionPoint;
struct Extraction {
  ExtractionKind kind;
  std::string_view name;  // "msr": lower case, the one spelling
  // The points on the master map, most salient first.
  absl::StatusOr<std::vector<AttentionPoint>> (*extract)(
      const cv::Mat& master, const DetectOptions& options);
};
absl::Span<const Extraction> Extractions();

// Each kind's one spelling and the parsers of the text forms (defined, with
// Extractions() and ChannelsText, in option_names.cc).
std::string_view SaliencyOpName(SaliencyOp op);        // "ph", "sym3d", ...
std::string_view ExtractionName(ExtractionKind kind);  // "msr", "wta", "tj"
std::string_view PyramidName(PyramidKind kind);  // "none", "simple", "itti"
// Each small option's table of names (core/base/name_table.h), read by its
// parser below and by the tools' help text.
absl::Span<const NamedValue<PyramidKind>> PyramidKinds();
absl::Span<const NamedValue<LevelCombination>> LevelCombinations();
absl::Span<const NamedValue<NormalizationKind>> NormalizationKinds();
absl::Span<const NamedValue<FusionKind>> FusionKinds();
// The names of Extractions(), joined by `separator`: "msr wta tj".
std::string ExtractionNames(std::string_view separator = " ");
// Parses "ph", "ph+sh+rso", ... into equally weighted channels.
absl::StatusOr<std::vector<SaliencyOp>> ParseSaliencyOps(std::string_view text);
absl::StatusOr<ExtractionKind> ParseExtraction(std::string_view text);
// "none" "simple" "itti"; "sum" "max"; "lin" "nms" "nlm"; "sum" "max". An
// unknown name is INVALID_ARGUMENT listing the known ones.
absl::StatusOr<PyramidKind> ParsePyramid(std::string_view text);
absl::StatusOr<LevelCombination> ParseLevelCombination(std::string_view text);
absl::StatusOr<NormalizationKind> ParseNormalization(std::string_view text);
absl::StatusOr<FusionKind> ParseFusion(std::string_view text);

// Most attention points one request may ask for.
inline constexpr int kMaxAttentionPoints = 100;

struct WeightedChannel {
  SaliencyOp op = SaliencyOp::kRso;
  float weight = 1.0f;  // >= 0; renormalised so the weights sum to 1
};

// "sym3d", "ph+sh+rso": the channels' names joined by '+', as
// ParseSaliencyOps reads them (weights left out).
std::string ChannelsText(const std::vector<WeightedChannel>& channels);

// The scene a request looks at: which sensor took it, at what resolution
// to work, where to look, and what is known of the support. Shared by
// Detect, Segment and SegmentIncremental (it is part of DetectOptions).
struct SceneOptions {
  // The sensor's noise model (core/frame/sensor_model.h); every
  // noise-dependent threshold follows it. kGeneric takes it from the
  // intrinsics.
  SensorKind sensor = SensorKind::kGeneric;
  // Frames wider than this are processed reduced (core/frame/frame_scale.h)
  // and their points, masks and maps come back at the input resolution,
  // pixels, [kMinProcessingWidth, kMaxProcessingWidth].
  int processing_width = kDefaultProcessingWidth;
  // Nothing outside it is considered; its depth range defaults to the
  // sensor's (3 m for a generic camera).
  Workspace workspace;
  // Gravity and the support plane, when the caller knows them.
  SupportHints support;
};

inline constexpr int kMinProcessingWidth = 160;
inline constexpr int kMaxProcessingWidth = 1920;

absl::Status Validate(const SceneOptions& options);

struct DetectOptions {
  // Channels of the master map (thesis eq. 2.42-2.44), each operator at
  // most once. The defaults of this struct are the combination that
  // measures best on the 45 OSD learn scenes (docs/attention-sweep.md):
  // SYM3D on the ITTI pyramid, split at surface edges, with TJ points;
  // HR 0.993, DC 0.184.
  std::vector<WeightedChannel> channels = {{SaliencyOp::kSym3d, 1.0f}};
  // Multi-scale pyramid (section 2.4): kNone is one level; kSimple and
  // kItti build each 3D channel's conspicuity map over the cloud pyramid.
  PyramidKind pyramid = PyramidKind::kItti;
  // Across-scale combination (eq. 2.40-2.41), used with a pyramid.
  LevelCombination level_combination = LevelCombination::kSum;
  // Normalisation of each map (eq. 2.37-2.39).
  NormalizationKind normalization = NormalizationKind::kLin;
  // Fusion of the channels into the master map (eq. 2.42-2.44).
  FusionKind fusion = FusionKind::kSum;
  // Attention-point extraction (section 2.5).
  ExtractionKind extraction = ExtractionKind::kTj;
  // Attention points to return at most, [1, kMaxAttentionPoints]. The
  // default is every salient region: TJ gives one point per region, so a
  // pile of fifteen objects gets fifteen points (and no object two, unless
  // its map falls apart); MSR and WTA stop when the map is exhausted or at
  // this cap.
  int max_points = kMaxAttentionPoints;
  // Regions of the master map smaller than this give no point: specks that
  // noise and the surface-edge split leave of an object's faces, not
  // objects. Given at a 525 px focal length (a Kinect's) and scaled by
  // (fx / 525)^2, so 150 px is about 3 x 3 cm seen from 1.2 m with any
  // sensor. Used by TJ (it overrides tj.min_component_pixels); 0 keeps
  // every region.
  int min_region_pixels = 150;
  // Return each channel's map in DetectResult::channel_maps.
  bool keep_channel_maps = false;
  // Fill small depth holes by colour-guided diffusion before anything else
  // (thesis section 2.2).
  bool fill_holes = false;
  // Fill speckled dropout (a dark surface whose depth the sensor returns
  // at scattered pixels only) from the plane through each missing pixel's
  // measured neighbours (core/frame/dropout_fill.h).
  bool fill_speckled_dropout = true;
  // Pyramid level SYM3D runs on without a pyramid: its k x k kernel must
  // span an object (level 2 of a 640x480 frame is 160x120).
  int sym3d_level = 2;
  // Zero the master map on occluding edges and concave creases
  // (FindSurfaceEdges) before extraction, so that touching objects fall
  // into separate components and regions.
  // Off, the master map is the thesis's; touching and stacked objects then
  // share one TJ component (learn scenes: HR 0.62 instead of 0.99).
  bool split_at_surface_edges = true;

  SceneOptions scene;

  // Options of each stage, documented with the stage. The noise-dependent
  // thresholds of support_plane and table_scene are set from the scene's
  // sensor model (core/pipeline/sensor_adaptation.h) when the scene is
  // prepared.
  HoleFillingOptions hole_filling;
  DropoutFillOptions dropout_fill;
  NormalOptions normals;
  SupportPlaneOptions support_plane;
  TableSceneOptions table_scene;
  SurfaceEdgeOptions surface_edges;
  PhOptions ph;
  ShOptions sh;
  RsoOptions rso;
  MsrOptions msr;
  Sym3dOptions sym3d;
  IttiOptions itti;
  HarelOptions harel;
  HouOptions hou;
  KootstraOptions kootstra;
  TargetColorOptions target_color;      // TARGET_COLOR: the requested colour
  LocationPriorOptions location_prior;  // LOCATION_PRIOR: centre and spread
  WtaOptions wta;
  TjOptions tj;
  CloudPyramidOptions cloud_pyramid;
  // Levels and scales of the feature pyramids; its kind, combination and
  // normalisation are taken from `pyramid`, `level_combination` and
  // `normalization` above.
  FeaturePyramidOptions feature_pyramid;
  NormalizationOptions normalization_options;
};

// Validates every field; errors are INVALID_ARGUMENT and name the field.
absl::Status Validate(const DetectOptions& options);

struct NamedMap {
  std::string name;  // "master" or SaliencyOpName
  cv::Mat map;       // CV_32FC1, [0, 1]
};

// Pixels, maps and masks of results are those of the frame as sent; a
// frame wider than the processing width was processed reduced.
struct DetectResult {
  std::vector<AttentionPoint> points;  // most salient first, 3D filled in
  cv::Mat master;                      // CV_32FC1, [0, 1], the frame's size
  std::vector<NamedMap> channel_maps;  // when keep_channel_maps
  SupportPlane plane;
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;
};

// The attention points of a master map (CV_32FC1, [0, 1]) by
// options.extraction (MSR, WTA or TJ with their options), at most
// options.max_points, most salient first; the 3D points are not filled in.
absl::StatusOr<std::vector<AttentionPoint>> ExtractAttentionPoints(
    const cv::Mat& master, const DetectOptions& options);

// What every pipeline computes first from a frame: the organized cloud with
// normals (hole-filled first when options.fill_holes), the support plane
// and the table scene, with the stages' timings ("fill_holes", "cloud",
// "normals", "support_plane").
struct PreparedScene {
  // At the processing resolution; `scale` maps it to the frame as sent.
  OrganizedCloud cloud;
  SupportPlane plane;
  TableScene table;
  // CV_8UC1, 255 on surface edges (FindSurfaceEdges with
  // options.surface_edges), when options.split_at_surface_edges; else
  // empty. Built beside the support plane when the scope has two threads.
  cv::Mat surface_edges;
  // The cloud pyramid the saliency channels read (BuildCloudPyramid with
  // CloudPyramidLevels(options)), when they read one (UsesCloudPyramid);
  // built beside the support plane when the scope has two threads.
  std::optional<CloudPyramid> pyramid;
  FrameScale scale;
  SensorModel sensor;  // the scene's, for the frame's intrinsics
  std::vector<StageTiming> timings;
};

// Every stage name RunDetect can report with the options it accepts today
// ("cloud", "normals", "support_plane", "saliency.<op>", "fusion",
// "extract.<kind>"), for metrics that must exist before the first call.
std::vector<std::string> DetectStageNames();

// `options` without the speckled-dropout fill: the training examples of
// the relation SVMs are taken from the surfaces the sensor measured. With
// the filled planes among them (synthetic dark objects), the relations
// learnt moved and OSD's leave-one-kind-out stacked F fell 0.922 -> 0.891.
DetectOptions MeasuredDepthOnly(DetectOptions options);

// The whole Detect path on a decoded frame: optional hole filling,
// organized cloud and normals,
// support plane, table scene, each channel's map, fusion, extraction.
// Errors: INVALID_ARGUMENT / UNIMPLEMENTED from Validate; NOT_FOUND when
// there is no support plane; whatever `interrupt` returns. What a library
// underneath throws (out of memory, an OpenCV bug) passes through to the
// caller's boundary (core/base/guarded.h).
absl::StatusOr<DetectResult> RunDetect(const RgbdFrame& frame,
                                       const DetectOptions& options,
                                       const InterruptCheck& interrupt = {});

// RunDetect's two halves, for pipelines that need the scene too
// (segmentation): PrepareScene validates `options` and builds the scene
// (errors as RunDetect's): the frame reduced to the processing width, the
// cloud within the workspace, normals, the support (searched, or the
// hinted plane's region) and the table scene; DetectOnScene computes the
// saliency maps and attention points on it, in the scene's (processing)
// pixels (its timings start at the first channel; `scene.timings` are not
// copied).
absl::StatusOr<PreparedScene> PrepareScene(
    const RgbdFrame& frame, const DetectOptions& options,
    const InterruptCheck& interrupt = {});
absl::StatusOr<DetectResult> DetectOnScene(
    const PreparedScene& scene, const DetectOptions& options,
    const InterruptCheck& interrupt = {});

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_DETECT_H_
