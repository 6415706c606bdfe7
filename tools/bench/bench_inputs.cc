#include "tools/bench/bench_inputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string_view>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/frame/image_codec.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/detect.h"
#include "core/saliency/rso.h"
#include "core/synth/room.h"
#include "core/synth/synth_scene.h"
#include "tools/eval/realsense_frames.h"

namespace fovea::bench {
namespace {

// Synthetic scenes the EBS model of the benchmarks is trained on (the timed
// ones are main.cc's kSynthSeeds, 1-4).
constexpr uint64_t kEbsTrainingSeeds[] = {101, 102, 103};

// Largest depth a 16UC1 millimetre pixel holds.
constexpr float kMaxWireDepthUnits = 65535.0f;

std::string_view View(const std::string& s) { return {s.data(), s.size()}; }

// Row-major rgb8 bytes of a CV_8UC3 RGB image.
std::string EncodeRgb8(const cv::Mat& rgb) {
  const size_t row_bytes = static_cast<size_t>(rgb.cols) * 3;
  std::string out(row_bytes * rgb.rows, '\0');
  for (int v = 0; v < rgb.rows; ++v) {
    std::memcpy(out.data() + v * row_bytes, rgb.ptr<uint8_t>(v), row_bytes);
  }
  return out;
}

// Depth in metres (NaN: no data) to 16-bit units of kWireDepthScale; 0 is
// no data, as a Kinect driver writes it.
cv::Mat ToDepthUnits(const cv::Mat& depth_m) {
  cv::Mat units(depth_m.size(), CV_16UC1);
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* in = depth_m.ptr<float>(v);
    uint16_t* out = units.ptr<uint16_t>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const float z = in[u];
      out[u] = std::isfinite(z) && z > 0.0f
                   ? static_cast<uint16_t>(std::min(
                         std::round(z / static_cast<float>(kWireDepthScale)),
                         kMaxWireDepthUnits))
                   : 0;
    }
  }
  return units;
}

// Little-endian row-major bytes of a CV_16UC1 image (x86 is little-endian,
// as the wire requires).
std::string EncodeDepth16(const cv::Mat& units) {
  const size_t row_bytes = static_cast<size_t>(units.cols) * 2;
  std::string out(row_bytes * units.rows, '\0');
  for (int v = 0; v < units.rows; ++v) {
    std::memcpy(out.data() + v * row_bytes, units.ptr<uint16_t>(v), row_bytes);
  }
  return out;
}

RawImage RawWire(uint32_t width, uint32_t height, std::string_view encoding,
                 uint32_t step, std::string_view data) {
  RawImage image;
  image.width = width;
  image.height = height;
  image.encoding = encoding;
  image.step = step;
  image.data = data;
  return image;
}

absl::Status StageError(const BenchScene& scene, std::string_view stage,
                        const absl::Status& status) {
  return absl::FailedPreconditionError(
      absl::StrCat(scene.name, ": ", AbslView(stage), ": ", status.ToString()));
}

void AddScene(std::string name, const RgbdFrame& frame, SceneList& scenes) {
  auto scene = std::make_unique<BenchScene>();
  scene->name = std::move(name);
  const absl::Status status = PrepareScene(frame, *scene);
  if (!status.ok()) {
    std::fprintf(stderr, "fovea-bench: skipping scene: %s\n",
                 status.ToString().c_str());
    return;
  }
  scenes.push_back(std::move(scene));
}

}  // namespace

absl::Status PrepareScene(const RgbdFrame& frame, BenchScene& scene) {
  const uint32_t width = static_cast<uint32_t>(frame.width());
  const uint32_t height = static_cast<uint32_t>(frame.height());

  scene.color_rgb8 = EncodeRgb8(frame.color);
  const cv::Mat depth_units = ToDepthUnits(frame.depth);
  scene.depth_16uc1 = EncodeDepth16(depth_units);

  cv::Mat bgr;
  cv::cvtColor(frame.color, bgr, cv::COLOR_RGB2BGR);
  absl::StatusOr<std::string> color_png = EncodePng(bgr);
  if (!color_png.ok()) {
    return StageError(scene, "encode colour PNG", color_png.status());
  }
  scene.color_png = *std::move(color_png);
  absl::StatusOr<std::string> depth_png = EncodePng(depth_units);
  if (!depth_png.ok()) {
    return StageError(scene, "encode depth PNG", depth_png.status());
  }
  scene.depth_png = *std::move(depth_png);

  scene.raw_wire = RawFrame{};
  scene.raw_wire.color =
      RawWire(width, height, "rgb8", width * 3, View(scene.color_rgb8));
  scene.raw_wire.depth =
      RawWire(width, height, "16UC1", width * 2, View(scene.depth_16uc1));
  scene.raw_wire.intrinsics = frame.intrinsics;
  scene.raw_wire.depth_scale = kWireDepthScale;

  scene.png_wire = RawFrame{};
  scene.png_wire.color.compressed = View(scene.color_png);
  scene.png_wire.depth.compressed = View(scene.depth_png);
  scene.png_wire.intrinsics = frame.intrinsics;
  scene.png_wire.depth_scale = kWireDepthScale;

  absl::StatusOr<RgbdFrame> decoded =
      DecodeFrame(scene.raw_wire, BenchFrameLimits());
  if (!decoded.ok()) return StageError(scene, "decode raw", decoded.status());
  scene.frame = *std::move(decoded);
  absl::StatusOr<RgbdFrame> from_png =
      DecodeFrame(scene.png_wire, BenchFrameLimits());
  if (!from_png.ok()) return StageError(scene, "decode PNG", from_png.status());

  const DetectOptions options;
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame, options.normals);
  if (!cloud.ok()) return StageError(scene, "cloud", cloud.status());
  scene.cloud = *std::move(cloud);
  absl::StatusOr<SupportPlane> plane =
      FindSupportPlane(scene.cloud, options.support_plane);
  if (!plane.ok()) return StageError(scene, "support plane", plane.status());
  scene.plane = *std::move(plane);
  scene.table =
      PrepareTableScene(scene.cloud, scene.plane, options.table_scene);
  absl::StatusOr<cv::Mat> rso =
      ComputeRsoSaliency(scene.cloud, scene.plane, scene.table, options.rso);
  if (!rso.ok()) return StageError(scene, "saliency.rso", rso.status());
  scene.rso_map = *std::move(rso);

  const absl::StatusOr<EbsModel>& ebs = BenchEbsModel();
  if (!ebs.ok()) return StageError(scene, "ebs model", ebs.status());
  scene.edge_probability = ebs->EdgeProbability(scene.cloud);
  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractAttentionPoints(scene.rso_map, options);
  if (!points.ok()) return StageError(scene, "attention", points.status());
  scene.fixation =
      points->empty()
          ? cv::Point(scene.cloud.width() / 2, scene.cloud.height() / 2)
          : cv::Point(points->front().u, points->front().v);
  return absl::OkStatus();
}

const absl::StatusOr<EbsModel>& BenchEbsModel() {
  static const absl::StatusOr<EbsModel>* const model = [] {
    std::vector<synth::SynthScene> scenes;
    std::vector<const LabelledFrame*> frames;
    for (const uint64_t seed : kEbsTrainingSeeds) {
      scenes.push_back(synth::GenerateScene(seed));
    }
    for (const synth::SynthScene& s : scenes) frames.push_back(&s.frame);
    return new absl::StatusOr<EbsModel>(
        EbsModel::Train(frames, EbsTrainOptions{}));
  }();
  return *model;
}

void AddSyntheticScenes(const std::vector<uint64_t>& seeds, SceneList& scenes) {
  for (const uint64_t seed : seeds) {
    synth::SynthScene synth = synth::GenerateScene(seed);
    AddScene(synth.frame.name, synth.frame.frame, scenes);
  }
}

void AddRoomScenes(const std::vector<uint64_t>& seeds, synth::RoomSensor sensor,
                   int width, int height, SceneList& scenes, int objects) {
  synth::RoomOptions options;
  options.sensor = sensor;
  options.width = width;
  options.height = height;
  if (objects > 0) {
    options.clutter.min_objects = objects;
    options.clutter.max_objects = objects;
  }
  for (const uint64_t seed : seeds) {
    synth::SynthScene room = synth::GenerateRoom(seed, options);
    AddScene(room.frame.name, room.frame.frame, scenes);
  }
}

void AddPileScenes(int objects, int count, uint64_t first_seed,
                   SceneList& scenes) {
  int added = 0;
  for (uint64_t seed = first_seed; seed < first_seed + 400 && added < count;
       ++seed) {
    synth::SynthScene pile = synth::GeneratePile(seed);
    int visible = 0;
    for (const synth::ObjectTruth& o : pile.objects) {
      visible += o.visible_pixels > 0 ? 1 : 0;
    }
    if (visible != objects) continue;
    AddScene(pile.frame.name, pile.frame.frame, scenes);
    ++added;
  }
}

absl::Status AddRawFrames(const std::string& dir, const Intrinsics& k,
                          const std::string& suffix, SceneList& scenes) {
  constexpr std::string_view kColor = "_color.png";
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    const std::string file = entry.path().filename().string();
    if (file.size() > kColor.size() &&
        file.compare(file.size() - kColor.size(), kColor.size(), kColor) == 0) {
      names.push_back(file.substr(0, file.size() - kColor.size()));
    }
  }
  std::sort(names.begin(), names.end());
  int found = 0;
  for (const std::string& name : names) {
    const std::optional<RgbdFrame> frame = eval::ReadRawFrame(dir, name, k);
    if (!frame) continue;
    ++found;
    AddScene(name + suffix, *frame, scenes);
  }
  if (found == 0) {
    return absl::NotFoundError(absl::StrCat(
        "no <name>_color.png with <name>_depth_mm.png in '", dir, "'"));
  }
  return absl::OkStatus();
}

absl::Status AddOsdScenes(const std::string& osd_dir, int max_scenes,
                          SceneList& scenes) {
  FOVEA_ASSIGN_OR_RETURN(std::vector<std::string> files,
                         ListPcdFiles(osd_dir + "/learn"));
  int added = 0;
  for (const std::string& path : files) {
    if (max_scenes > 0 && added >= max_scenes) break;
    absl::StatusOr<LabelledFrame> loaded = LoadOsdPcd(path);
    if (!loaded.ok()) {
      std::fprintf(stderr, "fovea-bench: skipping %s: %s\n", path.c_str(),
                   loaded.status().ToString().c_str());
      continue;
    }
    const size_t before = scenes.size();
    AddScene(loaded->name, loaded->frame, scenes);
    if (scenes.size() > before) ++added;
  }
  return absl::OkStatus();
}

}  // namespace fovea::bench
