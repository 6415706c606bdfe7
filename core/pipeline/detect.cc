#include "core/pipeline/detect.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/pipeline/channels.h"
#include "core/pipeline/saliency_registry.h"
#include "core/pipeline/sensor_adaptation.h"
#include "core/pyramid/fusion.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// Focal length pixel sizes are given at (a Kinect's), pixels.
constexpr double kReferenceFocalPx = 525.0;
// Deepest pyramid level SYM3D may be asked to run on (a 640x480 frame has
// 8 levels, 0..7).
constexpr int kMaxSym3dLevel = 7;

absl::Status Check(const InterruptCheck& interrupt) {
  return interrupt ? interrupt() : absl::OkStatus();
}

void FillPoints(const OrganizedCloud& cloud,
                std::vector<AttentionPoint>& points) {
  for (AttentionPoint& p : points) {
    const cv::Vec3f& q = cloud.xyz.at<cv::Vec3f>(p.v, p.u);
    p.point = {q[0], q[1], q[2]};
  }
}

}  // namespace

absl::Status Validate(const SceneOptions& options) {
  if (options.processing_width < kMinProcessingWidth ||
      options.processing_width > kMaxProcessingWidth) {
    return absl::InvalidArgumentError(absl::StrCat(
        "options.scene.processing_width must be in [", kMinProcessingWidth,
        ", ", kMaxProcessingWidth, "], got ", options.processing_width));
  }
  if (absl::Status s = Validate(options.workspace); !s.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.scene.", s.message()));
  }
  if (absl::Status s = Validate(options.support); !s.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.scene.", s.message()));
  }
  return absl::OkStatus();
}

absl::Status Validate(const DetectOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options.scene));
  if (options.channels.empty()) {
    return absl::InvalidArgumentError("options.saliency: no channel given");
  }
  for (size_t i = 0; i < options.channels.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (options.channels[j].op == options.channels[i].op) {
        return absl::InvalidArgumentError(absl::StrCat(
            "options.saliency: '",
            AbslView(SaliencyOpName(options.channels[i].op)),
            "' is given more than once; give each operator once with its "
            "weight"));
      }
    }
  }
  for (const WeightedChannel& c : options.channels) {
    if (!(c.weight >= 0.0f) || !std::isfinite(c.weight)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "options.saliency: weight of '", AbslView(SaliencyOpName(c.op)),
          "' must be finite and >= 0, got ", c.weight));
    }
    if (FindSaliencyOperator(c.op) == nullptr) {
      return absl::UnimplementedError(
          absl::StrCat("options.saliency: '", AbslView(SaliencyOpName(c.op)),
                       "' is not implemented yet"));
    }
  }
  if (options.max_points < 1 || options.max_points > kMaxAttentionPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.max_points must be in [1, ", kMaxAttentionPoints,
                     "], got ", options.max_points));
  }
  if (options.min_region_pixels < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.min_region_pixels must be >= 0, got ",
                     options.min_region_pixels));
  }
  if (options.sym3d_level < 0 || options.sym3d_level > kMaxSym3dLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.sym3d_level must be in [0, ", kMaxSym3dLevel,
                     "], got ", options.sym3d_level));
  }
  FOVEA_RETURN_IF_ERROR(Validate(options.hole_filling));
  FOVEA_RETURN_IF_ERROR(Validate(options.dropout_fill));
  FOVEA_RETURN_IF_ERROR(Validate(options.normals));
  FOVEA_RETURN_IF_ERROR(Validate(options.support_plane));
  FOVEA_RETURN_IF_ERROR(Validate(options.table_scene));
  FOVEA_RETURN_IF_ERROR(Validate(options.ph));
  FOVEA_RETURN_IF_ERROR(Validate(options.sh));
  FOVEA_RETURN_IF_ERROR(Validate(options.rso));
  FOVEA_RETURN_IF_ERROR(Validate(options.sym3d));
  FOVEA_RETURN_IF_ERROR(Validate(options.itti));
  FOVEA_RETURN_IF_ERROR(Validate(options.harel));
  FOVEA_RETURN_IF_ERROR(Validate(options.hou));
  FOVEA_RETURN_IF_ERROR(Validate(options.kootstra));
  FOVEA_RETURN_IF_ERROR(Validate(options.target_color));
  FOVEA_RETURN_IF_ERROR(Validate(options.location_prior));
  FOVEA_RETURN_IF_ERROR(Validate(options.wta));
  FOVEA_RETURN_IF_ERROR(Validate(options.tj));
  FOVEA_RETURN_IF_ERROR(Validate(options.surface_edges));
  FOVEA_RETURN_IF_ERROR(Validate(options.cloud_pyramid));
  FOVEA_RETURN_IF_ERROR(Validate(options.feature_pyramid));
  FOVEA_RETURN_IF_ERROR(Validate(options.normalization_options));
  return Validate(options.msr);
}

absl::StatusOr<std::vector<AttentionPoint>> ExtractAttentionPoints(
    const cv::Mat& master, const DetectOptions& options) {
  for (const Extraction& row : Extractions()) {
    if (row.kind == options.extraction) return row.extract(master, options);
  }
  return absl::InvalidArgumentError("options.extraction: unknown strategy");
}

std::vector<std::string> DetectStageNames() {
  std::vector<std::string> names = {"reduce", "fill_holes", "fill_dropout",
                                    "cloud",  "normals",    "support_plane",
                                    "fusion"};
  for (const SaliencyOperator& row : SaliencyOperators()) {
    names.push_back(absl::StrCat("saliency.", AbslView(row.name)));
  }
  for (const Extraction& row : Extractions()) {
    DetectOptions probe;
    probe.extraction = row.kind;
    if (Validate(probe).ok()) {
      names.push_back(absl::StrCat("extract.", AbslView(row.name)));
    }
  }
  return names;
}

absl::StatusOr<DetectResult> RunDetect(const RgbdFrame& frame,
                                       const DetectOptions& options,
                                       const InterruptCheck& interrupt) {
  const auto start = std::chrono::steady_clock::now();
  FOVEA_ASSIGN_OR_RETURN(PreparedScene scene,
                         PrepareScene(frame, options, interrupt));
  FOVEA_ASSIGN_OR_RETURN(DetectResult result,
                         DetectOnScene(scene, options, interrupt));
  result.timings.insert(result.timings.begin(), scene.timings.begin(),
                        scene.timings.end());
  // Back to the frame as sent.
  const FrameScale& scale = scene.scale;
  if (scale.reduced()) {
    for (AttentionPoint& p : result.points) {
      const cv::Point q = scale.ToInput({p.u, p.v});
      p.u = q.x;
      p.v = q.y;
    }
    result.master = scale.MapToInput(result.master);
    for (NamedMap& m : result.channel_maps) m.map = scale.MapToInput(m.map);
    result.plane.inliers = scale.MaskToInput(result.plane.inliers);
    result.plane.inlier_count = cv::countNonZero(result.plane.inliers);
  }
  result.total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

DetectOptions MeasuredDepthOnly(DetectOptions options) {
  options.fill_speckled_dropout = false;
  return options;
}

absl::StatusOr<PreparedScene> PrepareScene(const RgbdFrame& frame,
                                           const DetectOptions& options,
                                           const InterruptCheck& interrupt) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  PreparedScene scene;
  StageClock clock(scene.timings);
  scene.sensor = SensorModelFor(options.scene.sensor, frame.intrinsics);

  ReducedFrame reduced =
      ReduceForProcessing(frame, options.scene.processing_width);
  scene.scale = reduced.scale;
  if (scene.scale.reduced()) clock.Lap("reduce");
  RgbdFrame filled_frame;
  const RgbdFrame* input = &reduced.frame;
  // The input from now on: `depth` filled, the colour shared.
  const auto use_filled = [&](cv::Mat depth) {
    filled_frame.color = input->color;  // shares the pixels
    filled_frame.intrinsics = input->intrinsics;
    filled_frame.depth = std::move(depth);
    input = &filled_frame;
  };
  if (options.fill_holes) {
    FOVEA_ASSIGN_OR_RETURN(FilledDepth filled,
                           FillDepthHoles(reduced.frame, options.hole_filling));
    use_filled(std::move(filled.depth));
    clock.Lap("fill_holes");
  }
  if (options.fill_speckled_dropout) {
    FOVEA_ASSIGN_OR_RETURN(
        FilledDepth filled,
        FillSpeckledDropout(options.dropout_fill, scene.sensor, input->color,
                            input->depth, interrupt));
    if (filled.filled_pixels > 0) use_filled(std::move(filled.depth));
    clock.Lap("fill_dropout");
  }
  scene.cloud = BackProject(*input);
  ApplyWorkspace(options.scene.workspace, scene.sensor, scene.cloud);
  clock.Lap("cloud");
  EstimateNormals(options.normals, scene.cloud);
  clock.Lap("normals");
  FOVEA_RETURN_IF_ERROR(Check(interrupt));

  // The support, the surface edges and the cloud pyramid need only the
  // cloud: with two threads, the support beside the other two.
  SupportPlaneOptions support_options = options.support_plane;
  AdaptToSensor(scene.sensor, support_options);
  absl::StatusOr<SupportPlane> plane;
  const auto find_support = [&] {
    plane =
        FindSupportPlane(scene.cloud, support_options, options.scene.support);
  };
  absl::Status pyramid = absl::OkStatus();
  const auto edges_and_pyramid = [&] {
    if (options.split_at_surface_edges) {
      scene.surface_edges =
          FindSurfaceEdges(scene.cloud, options.surface_edges);
    }
    if (UsesCloudPyramid(options)) {
      // The geometric operators read the levels' points and normals only:
      // no colour pyramid.
      OrganizedCloud geometry = scene.cloud;  // shares the pixels
      geometry.color = cv::Mat();
      absl::StatusOr<CloudPyramid> built =
          BuildCloudPyramid(geometry, CloudPyramidLevels(options));
      if (built.ok()) {
        scene.pyramid = *std::move(built);
      } else {
        pyramid = built.status();
      }
    }
  };
  ParallelInvoke(find_support, edges_and_pyramid);
  FOVEA_RETURN_IF_ERROR(plane.status());
  FOVEA_RETURN_IF_ERROR(pyramid);
  scene.plane = *std::move(plane);
  TableSceneOptions table_options = options.table_scene;
  AdaptToSensor(scene.sensor, table_options);
  scene.table = PrepareTableScene(scene.cloud, scene.plane, table_options);
  clock.Lap("support_plane");
  FOVEA_RETURN_IF_ERROR(Check(interrupt));
  return scene;
}

absl::StatusOr<DetectResult> DetectOnScene(const PreparedScene& scene,
                                           const DetectOptions& options,
                                           const InterruptCheck& interrupt) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const auto start = std::chrono::steady_clock::now();
  DetectResult result;
  StageClock clock(result.timings);
  const OrganizedCloud& cloud = scene.cloud;

  ChannelComputer channels(
      cloud, scene.plane, scene.table, options,
      scene.pyramid.has_value() ? &*scene.pyramid : nullptr);
  std::vector<NamedMap> maps;
  for (const WeightedChannel& c : options.channels) {
    FOVEA_ASSIGN_OR_RETURN(cv::Mat map, channels.Compute(c.op));
    maps.push_back({std::string(SaliencyOpName(c.op)), std::move(map)});
    clock.Lap(absl::StrCat("saliency.", AbslView(SaliencyOpName(c.op))));
    FOVEA_RETURN_IF_ERROR(Check(interrupt));
  }
  std::vector<cv::Mat> channel_maps;
  std::vector<float> weights;
  for (size_t i = 0; i < maps.size(); ++i) {
    channel_maps.push_back(maps[i].map);
    weights.push_back(options.channels[i].weight);
  }
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat master,
      FuseChannels(channel_maps, weights,
                   options.fusion == FusionKind::kMax ? ChannelFusion::kMax
                                                      : ChannelFusion::kSum));
  result.master = std::move(master);
  if (options.split_at_surface_edges) {
    result.master.setTo(0.0f,
                        scene.surface_edges.empty()
                            ? FindSurfaceEdges(cloud, options.surface_edges)
                            : scene.surface_edges);
  }
  NormalizeLinear(result.master);
  clock.Lap("fusion");

  // TJ's smallest region is given at a 525 px focal length.
  DetectOptions extraction = options;
  const double focal_ratio = cloud.intrinsics.fx / kReferenceFocalPx;
  extraction.tj.min_component_pixels = static_cast<int>(
      std::lround(options.min_region_pixels * focal_ratio * focal_ratio));
  FOVEA_ASSIGN_OR_RETURN(std::vector<AttentionPoint> points,
                         ExtractAttentionPoints(result.master, extraction));
  result.points = std::move(points);
  FillPoints(cloud, result.points);
  clock.Lap(
      absl::StrCat("extract.", AbslView(ExtractionName(options.extraction))));

  if (options.keep_channel_maps) result.channel_maps = std::move(maps);
  result.plane = scene.plane;
  result.total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

}  // namespace fovea
