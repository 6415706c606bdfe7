#ifndef FOVEA_CORE_SYNTH_ROOM_H_
#define FOVEA_CORE_SYNTH_ROOM_H_

#include <cstdint>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// Synthetic rooms: what a robot's camera sees when it looks at a table in
// an office, uncropped. A support table (top, edge and legs) with random
// clutter on it, standing on a textured floor; walls; often a second table
// behind or beside it, at the same height or another, with its own objects;
// cabinets, chairs and boxes on the floor. Rendered with one of two sensor
// noise models at 640x480 up to 1280x720. Ground truth: the objects on the
// support table are the objects (labels 20, 30, ...); the support table is
// label 1 and everything else is a background label 2..6 (synth_scene.h),
// so a mask on it is a false object; SynthScene::table_normal_camera / d is
// the support plane.

enum class RoomSensor {
  kKinectV1,      // 640x480 at fx 525 (scaled with the width), KinectV1Noise
  kActiveStereo,  // fx 613 at 640x480 (4:3) or 920 at 1280x720 (16:9),
                  // ActiveStereoNoise
  kTimeOfFlight,  // fx 504 at 640x576 (Azure Kinect NFOV), TimeOfFlightNoise
};

// "kinect_v1", "active_stereo", "time_of_flight".
std::string_view RoomSensorName(RoomSensor sensor);
// The sensor's part of a synthetic scene's name: "" for the Kinect v1 (the
// names scenes had before there were others), "as-", "tof-".
std::string_view RoomSensorTag(RoomSensor sensor);
absl::StatusOr<RoomSensor> ParseRoomSensor(std::string_view text);

struct RoomOptions {
  RoomSensor sensor = RoomSensor::kKinectV1;
  int width = 640;   // pixels, [160, 1920]
  int height = 480;  // pixels, [120, 1080]
  // The clutter on the support table (RandomSceneOptions; the camera fields
  // are not used, rooms place their own camera).
  RandomSceneOptions clutter = [] {
    RandomSceneOptions o;
    o.min_objects = 2;
    o.max_objects = 8;
    return o;
  }();
  // A second table in view: probability, and the probability that its top
  // is at the support table's height (the same plane, beyond a gap).
  float second_table_probability = 0.7f;
  float same_height_probability = 0.5f;
  // Cabinets, chairs and boxes on the floor, at most this many of each.
  int max_cabinets = 2;
  int max_chairs = 2;
  int max_floor_boxes = 2;
  // Camera height above the floor, metres (a robot's head).
  float min_camera_height = 0.95f;
  float max_camera_height = 1.55f;
};

// OK, or INVALID_ARGUMENT naming the field.
absl::Status Validate(const RoomOptions& options);

// The room of `seed`, deterministic. Precondition (checked):
// Validate(options) is OK.
SceneSpec RandomRoomSpec(uint64_t seed, const RoomOptions& options);

// The noise model of options.sensor.
NoiseOptions RoomNoise(RoomSensor sensor);

// The frame `sensor` sends unless asked for another size: 640x480, or
// 640x576 for time of flight (whose nearly square frame is how a generic
// camera is recognised as one, core/frame/sensor_model.h).
cv::Size SensorFrameSize(RoomSensor sensor);

// The pinhole intrinsics of `sensor` at width x height pixels, as
// RoomSensor describes them (the Kinect's principal point at the image
// centre, the active stereo's a few pixels right of and below it).
Intrinsics SensorIntrinsics(RoomSensor sensor, int width, int height);

// RandomRoomSpec rendered with RoomNoise, noise seeded by `seed`.
SynthScene GenerateRoom(uint64_t seed, const RoomOptions& options);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_ROOM_H_
