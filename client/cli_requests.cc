// fovea-client's request flags and the requests they ask for
// (cli_requests.h).
#include "client/cli_requests.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "client/option_names.h"
#include "core/base/status_macros.h"

// The frame.
ABSL_FLAG(std::string, color, "", "colour image file, PNG or JPEG, sent as is");
ABSL_FLAG(std::string, depth, "",
          "depth image file, 16-bit grey PNG in --depth_scale units, sent as "
          "is");
ABSL_FLAG(std::string, pcd, "",
          "OSD PCD file, sent raw as rgb8 + 32FC1 (OSD Kinect intrinsics "
          "unless --fx/--fy/--cx/--cy)");
ABSL_FLAG(std::optional<uint64_t>, synthetic, std::nullopt,
          "seed of a built-in synthetic table scene, sent raw");
ABSL_FLAG(std::optional<double>, fx, std::nullopt,
          "focal length x, pixels (default 525, OSD Kinect v1)");
ABSL_FLAG(std::optional<double>, fy, std::nullopt,
          "focal length y, pixels (default 525)");
ABSL_FLAG(std::optional<double>, cx, std::nullopt,
          "principal point column, pixels (default 319.5)");
ABSL_FLAG(std::optional<double>, cy, std::nullopt,
          "principal point row, pixels (default 239.5)");
ABSL_FLAG(double, depth_scale, 0.001, "metres per unit of a 16-bit depth PNG");
ABSL_FLAG(std::string, frame_id, "", "camera frame id, echoed back");
ABSL_FLAG(std::string, request_id, "",
          "request id, echoed back (default: generated)");

// Detect options (empty = the server's default).
// The lists of names in the help text are read from the contract's enums
// (client/option_names.h), as the flags' values are.
ABSL_FLAG(std::string, saliency, "",
          absl::StrCat("saliency channels: ",
                       fovea::client::NameList(
                           *fovea::v1::SaliencyOperator_descriptor(), ", "),
                       "; combine with '+' (equal weights) or give weights as "
                       "name:w, e.g. ph+sh+rso, ph:2+rso:1"));
ABSL_FLAG(
    std::string, extract, "",
    absl::StrCat("attention points: ",
                 fovea::client::NameList(*fovea::v1::Extraction_descriptor())));
ABSL_FLAG(std::string, pyramid, "",
          absl::StrCat("pyramid: ", fovea::client::NameList(
                                        *fovea::v1::Pyramid_descriptor())));
ABSL_FLAG(std::string, norm, "",
          absl::StrCat(
              "map normalisation: ",
              fovea::client::NameList(*fovea::v1::Normalization_descriptor())));
ABSL_FLAG(std::string, combine, "",
          absl::StrCat("pyramid level combination: ",
                       fovea::client::NameList(
                           *fovea::v1::LevelCombination_descriptor())));
ABSL_FLAG(
    std::string, fusion, "",
    absl::StrCat("channel fusion: ",
                 fovea::client::NameList(*fovea::v1::Fusion_descriptor())));
ABSL_FLAG(bool, maps, false, "ask for each channel's saliency map");
ABSL_FLAG(std::string, target_color, "",
          "target_color operator: the colour looked for, R,G,B (0-255), "
          "e.g. 200,30,30");
ABSL_FLAG(std::string, location_prior, "",
          "location_prior operator: the pixel the prior is centred on, U,V "
          "(column,row)");
ABSL_FLAG(double, location_sigma, 0.0,
          "location_prior operator: its standard deviation, pixels (0: the "
          "server's default)");
ABSL_FLAG(std::optional<bool>, split_edges, std::nullopt,
          "split the master map at surface edges before extraction "
          "(unset: the server's default; false: the thesis's map)");
ABSL_FLAG(int32_t, points, 0,
          "number of attention points at most, 0 = the server's default "
          "(one per salient region, at most 100)");

// The scene.
ABSL_FLAG(
    std::string, sensor, "",
    absl::StrCat("depth noise model: ",
                 fovea::client::NameList(*fovea::v1::SensorModel_descriptor()),
                 " (default generic: chosen from the intrinsics)"));
ABSL_FLAG(int32_t, processing_width, 0,
          "frames wider than this are processed reduced, pixels (0: the "
          "server's 640)");
ABSL_FLAG(std::string, gravity, "",
          "X,Y,Z: unit vector pointing down in the camera frame");
ABSL_FLAG(std::string, support_plane, "",
          "NX,NY,NZ,D: the support plane n . p + d = 0 (camera frame, "
          "metres), given instead of searched");
ABSL_FLAG(std::string, workspace_box, "",
          "MINX,MINY,MINZ,MAXX,MAXY,MAXZ: only points inside this camera-frame "
          "box, metres");
ABSL_FLAG(double, min_depth, 0.0,
          "nearest depth considered, metres (0: the sensor's)");
ABSL_FLAG(double, max_depth, 0.0,
          "farthest depth considered, metres (0: the sensor's)");

// Segmentation.
ABSL_FLAG(std::string, method, "",
          absl::StrCat("segment: ",
                       fovea::client::NameList(
                           *fovea::v1::SegmentationMethod_descriptor())));
ABSL_FLAG(int32_t, max_objects, 0, "segment: most objects, 0 = no limit");
ABSL_FLAG(std::string, seeds, "",
          "segment: seed pixels 'u,v;u,v;...' used in this order instead of "
          "the server's attention points (e.g. where a person pointed); "
          "segment-incremental: attention points, a Gaussian of saliency at "
          "each, the first the most salient");
ABSL_FLAG(std::string, object_points, "",
          "segment: each object's points too: xyz (float32, metres, camera "
          "frame) | indices (v * width + u); empty: none");
ABSL_FLAG(int32_t, max_points, 0,
          "segment: with --object_points, at most this many per object, "
          "evenly spread (0: all)");
ABSL_FLAG(std::string, frames, "",
          "track: a folder of frames <n>_color.png and <n>_depth.png (16-bit, "
          "--depth_scale units), taken in the order of <n>");
ABSL_FLAG(double, fps, 0.0,
          "track: send the frames at this rate, as a camera would (the server "
          "answers the freshest); 0: each after the previous answer");
ABSL_FLAG(double, time_budget_ms, 0.0,
          "segment-incremental: time budget, milliseconds, 0 = none");

namespace fovea::client {
namespace {

// `count` comma-separated numbers of flag `name`; INVALID_ARGUMENT naming
// it otherwise.
absl::StatusOr<std::vector<double>> Numbers(const std::string& name,
                                            const std::string& text,
                                            size_t count) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    double value = 0.0;
    if (!absl::SimpleAtod(part, &value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": '", part, "' is not a number"));
    }
    values.push_back(value);
  }
  if (values.size() != count) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": expected ", count,
                     " comma-separated numbers, got ", values.size()));
  }
  return values;
}

// "u,v;u,v" into pixels; empty text is no seeds.
absl::StatusOr<std::vector<std::pair<uint32_t, uint32_t>>> ParseSeeds(
    const std::string& text) {
  std::vector<std::pair<uint32_t, uint32_t>> seeds;
  for (absl::string_view item : absl::StrSplit(text, ';', absl::SkipEmpty())) {
    const std::vector<absl::string_view> uv = absl::StrSplit(item, ',');
    uint32_t u = 0;
    uint32_t v = 0;
    if (uv.size() != 2 || !absl::SimpleAtoi(uv[0], &u) ||
        !absl::SimpleAtoi(uv[1], &v)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "seeds: '", item, "' is not a pixel 'u,v' (columns, rows)"));
    }
    seeds.emplace_back(u, v);
  }
  return seeds;
}

// The scene options of the flags (the server validates the values).
absl::Status SceneFromFlags(fovea::v1::SceneOptions& scene) {
  if (const std::string sensor = absl::GetFlag(FLAGS_sensor); !sensor.empty()) {
    FOVEA_ASSIGN_OR_RETURN(const fovea::v1::SensorModel model,
                           ParseSensorModel(sensor));
    scene.set_sensor(model);
  }
  if (absl::GetFlag(FLAGS_processing_width) < 0) {
    return absl::InvalidArgumentError("processing_width: must be >= 0");
  }
  scene.set_processing_width(
      static_cast<uint32_t>(absl::GetFlag(FLAGS_processing_width)));
  if (const std::string g = absl::GetFlag(FLAGS_gravity); !g.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<double> v, Numbers("gravity", g, 3));
    scene.mutable_gravity()->set_x((v)[0]);
    scene.mutable_gravity()->set_y((v)[1]);
    scene.mutable_gravity()->set_z((v)[2]);
  }
  if (const std::string p = absl::GetFlag(FLAGS_support_plane); !p.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<double> v,
                           Numbers("support_plane", p, 4));
    fovea::v1::Plane* plane = scene.mutable_support_plane();
    plane->mutable_normal()->set_x((v)[0]);
    plane->mutable_normal()->set_y((v)[1]);
    plane->mutable_normal()->set_z((v)[2]);
    plane->set_d((v)[3]);
  }
  const std::string box = absl::GetFlag(FLAGS_workspace_box);
  const double min_depth = absl::GetFlag(FLAGS_min_depth);
  const double max_depth = absl::GetFlag(FLAGS_max_depth);
  if (!box.empty() || min_depth != 0.0 || max_depth != 0.0) {
    fovea::v1::Workspace* w = scene.mutable_workspace();
    w->set_min_depth_m(min_depth);
    w->set_max_depth_m(max_depth);
    if (!box.empty()) {
      FOVEA_ASSIGN_OR_RETURN(std::vector<double> v,
                             Numbers("workspace_box", box, 6));
      fovea::v1::Box* b = w->mutable_box();
      b->mutable_min()->set_x((v)[0]);
      b->mutable_min()->set_y((v)[1]);
      b->mutable_min()->set_z((v)[2]);
      b->mutable_max()->set_x((v)[3]);
      b->mutable_max()->set_y((v)[4]);
      b->mutable_max()->set_z((v)[5]);
    }
  }
  return absl::OkStatus();
}

}  // namespace

std::string RequestId() {
  std::string id = absl::GetFlag(FLAGS_request_id);
  if (id.empty()) id = absl::StrCat("cli-", absl::ToUnixMicros(absl::Now()));
  return id;
}

absl::StatusOr<LoadedFrame> FrameFromFlags() {
  FrameSource source;
  source.color_path = absl::GetFlag(FLAGS_color);
  source.depth_path = absl::GetFlag(FLAGS_depth);
  source.pcd_path = absl::GetFlag(FLAGS_pcd);
  source.synthetic_seed = absl::GetFlag(FLAGS_synthetic);
  source.fx = absl::GetFlag(FLAGS_fx);
  source.fy = absl::GetFlag(FLAGS_fy);
  source.cx = absl::GetFlag(FLAGS_cx);
  source.cy = absl::GetFlag(FLAGS_cy);
  source.depth_scale = absl::GetFlag(FLAGS_depth_scale);
  source.frame_id = absl::GetFlag(FLAGS_frame_id);
  return LoadFrame(source);
}

absl::StatusOr<std::vector<FrameSource>> TrackFramesFromFlags() {
  const std::string dir = absl::GetFlag(FLAGS_frames);
  if (dir.empty()) {
    return absl::InvalidArgumentError("--frames: a folder is required");
  }
  std::error_code error;
  std::vector<std::pair<uint64_t, std::string>> numbered;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    constexpr absl::string_view kSuffix = "_color.png";
    if (!absl::EndsWith(name, kSuffix)) continue;
    uint64_t n = 0;
    if (!absl::SimpleAtoi(name.substr(0, name.size() - kSuffix.size()), &n)) {
      continue;
    }
    numbered.emplace_back(n, name.substr(0, name.size() - kSuffix.size()));
  }
  if (error) {
    return absl::NotFoundError(
        absl::StrCat("--frames: cannot read '", dir, "': ", error.message()));
  }
  if (numbered.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--frames: no <n>_color.png in '", dir, "'"));
  }
  std::sort(numbered.begin(), numbered.end());
  std::vector<FrameSource> sources;
  for (const auto& [n, stem] : numbered) {
    FrameSource source;
    source.color_path =
        (std::filesystem::path(dir) / (stem + "_color.png")).string();
    source.depth_path =
        (std::filesystem::path(dir) / (stem + "_depth.png")).string();
    if (!std::filesystem::exists(source.depth_path)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--frames: ", source.color_path, " has no ", stem, "_depth.png"));
    }
    source.fx = absl::GetFlag(FLAGS_fx);
    source.fy = absl::GetFlag(FLAGS_fy);
    source.cx = absl::GetFlag(FLAGS_cx);
    source.cy = absl::GetFlag(FLAGS_cy);
    source.depth_scale = absl::GetFlag(FLAGS_depth_scale);
    source.frame_id = absl::GetFlag(FLAGS_frame_id);
    sources.push_back(std::move(source));
  }
  return sources;
}

double TrackFpsFromFlags() { return absl::GetFlag(FLAGS_fps); }

// Detect options from the flags; INVALID_ARGUMENT naming a bad one.
absl::StatusOr<fovea::v1::DetectOptions> DetectOptionsFromFlags(
    bool return_saliency_map) {
  fovea::v1::DetectOptions options;
  FOVEA_ASSIGN_OR_RETURN(std::vector<fovea::v1::WeightedOperator> saliency,
                         ParseSaliency(absl::GetFlag(FLAGS_saliency)));
  for (fovea::v1::WeightedOperator& op : saliency) {
    *options.add_saliency() = std::move(op);
  }
  // Each enum flag: parse when given, leave UNSPECIFIED otherwise.
  auto set = [](const std::string& text, auto parse, auto setter) {
    if (text.empty()) return absl::OkStatus();
    FOVEA_ASSIGN_OR_RETURN(auto value, parse(text));
    setter(value);
    return absl::OkStatus();
  };
  for (absl::Status status : {
           set(absl::GetFlag(FLAGS_extract), ParseExtraction,
               [&](auto v) { options.set_extraction(v); }),
           set(absl::GetFlag(FLAGS_pyramid), ParsePyramid,
               [&](auto v) { options.set_pyramid(v); }),
           set(absl::GetFlag(FLAGS_norm), ParseNormalization,
               [&](auto v) { options.set_normalization(v); }),
           set(absl::GetFlag(FLAGS_combine), ParseLevelCombination,
               [&](auto v) { options.set_level_combination(v); }),
           set(absl::GetFlag(FLAGS_fusion), ParseFusion,
               [&](auto v) { options.set_fusion(v); }),
       }) {
    if (!status.ok()) return status;
  }
  const int32_t points = absl::GetFlag(FLAGS_points);
  if (points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("points: must be >= 0, got ", points));
  }
  options.set_max_points(static_cast<uint32_t>(points));
  options.set_return_channel_maps(absl::GetFlag(FLAGS_maps));
  if (const std::string text = absl::GetFlag(FLAGS_target_color);
      !text.empty()) {
    FOVEA_ASSIGN_OR_RETURN(const auto rgb, ParseRgb("--target_color", text));
    for (const uint32_t value : rgb) options.add_target_color_rgb(value);
  }
  if (const std::string text = absl::GetFlag(FLAGS_location_prior);
      !text.empty()) {
    FOVEA_ASSIGN_OR_RETURN(*options.mutable_location_prior(),
                           ParsePixel("--location_prior", text));
  }
  if (const double sigma = absl::GetFlag(FLAGS_location_sigma); sigma != 0.0) {
    if (!(sigma > 0.0) || !std::isfinite(sigma)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--location_sigma: ", sigma, " is not a number of pixels > 0"));
    }
    options.set_location_prior_sigma_px(sigma);
  }
  if (const std::optional<bool> split = absl::GetFlag(FLAGS_split_edges)) {
    options.set_split_at_surface_edges(*split);
  }
  options.set_return_saliency_map(return_saliency_map);
  FOVEA_RETURN_IF_ERROR(SceneFromFlags(*options.mutable_scene()));
  return options;
}

absl::StatusOr<SegmentParameters> SegmentParametersFromFlags() {
  SegmentParameters segment;
  if (!absl::GetFlag(FLAGS_method).empty()) {
    FOVEA_ASSIGN_OR_RETURN(
        segment.method, ParseSegmentationMethod(absl::GetFlag(FLAGS_method)));
  }
  segment.max_objects = absl::GetFlag(FLAGS_max_objects);
  segment.time_budget_ms = absl::GetFlag(FLAGS_time_budget_ms);
  if (segment.max_objects < 0 || segment.time_budget_ms < 0.0) {
    return absl::InvalidArgumentError(
        "max_objects, time_budget_ms: must be >= 0");
  }
  FOVEA_ASSIGN_OR_RETURN(segment.seeds, ParseSeeds(absl::GetFlag(FLAGS_seeds)));
  const std::string points = absl::GetFlag(FLAGS_object_points);
  if (points == "xyz") {
    segment.object_points.set_format(
        fovea::v1::ObjectPointsOptions::FORMAT_XYZ);
  } else if (points == "indices") {
    segment.object_points.set_format(
        fovea::v1::ObjectPointsOptions::FORMAT_INDICES);
  } else if (!points.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--object_points: '", points, "' is not xyz or indices"));
  }
  if (absl::GetFlag(FLAGS_max_points) < 0) {
    return absl::InvalidArgumentError("--max_points: must be >= 0");
  }
  segment.object_points.set_max_points(
      static_cast<uint32_t>(absl::GetFlag(FLAGS_max_points)));
  return segment;
}

}  // namespace fovea::client
