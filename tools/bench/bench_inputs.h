#ifndef FOVEA_TOOLS_BENCH_BENCH_INPUTS_H_
#define FOVEA_TOOLS_BENCH_BENCH_INPUTS_H_

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/frame/frame_decode.h"
#include "core/frame/organized_cloud.h"
#include "core/frame/rgbd_frame.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"
#include "core/segmentation/ebs.h"
#include "core/synth/room.h"

namespace fovea::bench {

// One benchmark input: a decoded 640x480 frame, the same frame as it would
// arrive on the wire (raw rgb8 + 16UC1 millimetres, and PNG + 16-bit PNG),
// and the output of every stage before saliency, so that each stage can be
// timed on its own. Owns every buffer the RawFrame views point into, so it
// is neither copied nor moved (the views would dangle); see SceneList.
struct BenchScene {
  BenchScene() = default;
  BenchScene(const BenchScene&) = delete;
  BenchScene& operator=(const BenchScene&) = delete;

  std::string name;  // "synth-3", "learn6"
  RgbdFrame frame;   // as decoded from `raw_wire`

  // Wire forms. `raw_wire` and `png_wire` view the buffers below.
  std::string color_rgb8;   // height rows of width * 3 bytes
  std::string depth_16uc1;  // height rows of width * 2 bytes, little-endian
  std::string color_png;    // PNG file, 8-bit, 3 channels
  std::string depth_png;    // PNG file, 16-bit, 1 channel, millimetres
  RawFrame raw_wire;
  RawFrame png_wire;

  // Stage outputs with the default DetectOptions.
  OrganizedCloud cloud;  // with normals
  SupportPlane plane;
  TableScene table;
  cv::Mat rso_map;  // CV_32FC1, input to the MSR case
  // EBS inputs: the edge probability map of BenchEbsModel() and the first
  // attention point of `rso_map` (default extraction; the image centre if
  // there is none), where the contour case segments.
  cv::Mat edge_probability;  // CV_32FC1, [0, 1]
  cv::Point fixation;
};

using SceneList = std::vector<std::unique_ptr<BenchScene>>;

// Metres per 16-bit depth unit on the wire (the OSD frames' unit).
inline constexpr double kWireDepthScale = 0.001;

// The largest frame the benchmarks decode.
inline FrameLimits BenchFrameLimits() { return FrameLimits{}; }

// Fills the wire forms of `scene` from `scene.frame` (depth rounded to
// whole millimetres), decodes the raw form back into `scene.frame` (so all
// cases see exactly what the wire carries) and runs the stages up to the
// RSO map and the EBS edge probability map. FAILED_PRECONDITION naming the
// scene and the stage when one fails (e.g. no support plane).
absl::Status PrepareScene(const RgbdFrame& frame, BenchScene& scene);

// The EBS model of the EBS cases, trained once (on first use) on synthetic
// scenes other than the timed ones.
const absl::StatusOr<EbsModel>& BenchEbsModel();

// Synthetic scenes from core/synth, one per seed. Scenes whose preparation
// fails are left out with a line on stderr.
void AddSyntheticScenes(const std::vector<uint64_t>& seeds, SceneList& scenes);

// Synthetic rooms (core/synth/room.h) of one sensor and size, one per
// seed: uncropped frames with floor, walls and furniture around the table.
// `objects` > 0: that many objects on the table (as many as fit), else the
// rooms' 2-8.
void AddRoomScenes(const std::vector<uint64_t>& seeds, synth::RoomSensor sensor,
                   int width, int height, SceneList& scenes, int objects = 0);

// Synthetic piles (core/synth GeneratePile) of exactly `objects` visible
// objects: the first `count` such piles from seed `first_seed` upwards
// (at most 400 seeds tried).
void AddPileScenes(int objects, int count, uint64_t first_seed,
                   SceneList& scenes);

// Raw, uncropped frames as a robot sends them: every
// `<name>_color.png` with its `<name>_depth_mm.png` (16-bit millimetres, 0
// = none) in `dir`, in name order, with intrinsics `k`; the scenes are
// named `<name>` + `suffix`. The OSD folder's frames/ (its raw Kinect
// frame, intrinsics kKinectV1Intrinsics) and the RealSense folder are
// such. Frames whose preparation fails are left out with a line on
// stderr; NOT_FOUND when `dir` holds none.
absl::Status AddRawFrames(const std::string& dir, const Intrinsics& k,
                          const std::string& suffix, SceneList& scenes);

// The OSD learn*.pcd scenes of `osd_dir`/learn (all of them when
// `max_scenes` <= 0). Scenes whose preparation fails are left out with a
// line on stderr; an error when the folder cannot be listed.
absl::Status AddOsdScenes(const std::string& osd_dir, int max_scenes,
                          SceneList& scenes);

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_BENCH_INPUTS_H_
