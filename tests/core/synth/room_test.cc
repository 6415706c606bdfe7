#include "core/synth/room.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "core/frame/osd_pcd.h"
#include "core/frame/sensor_model.h"
#include "core/synth/raycast.h"

namespace fovea::synth {
namespace {

int CountLabel(const cv::Mat& labels, int label) {
  return cv::countNonZero(labels == label);
}

TEST(RoomTest, SameSeedSameRoom) {
  const SynthScene a = GenerateRoom(11, {});
  const SynthScene b = GenerateRoom(11, {});
  EXPECT_EQ(cv::norm(a.frame.labels, b.frame.labels, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.frame.frame.color, b.frame.frame.color, cv::NORM_INF),
            0.0);
  const SynthScene c = GenerateRoom(12, {});
  EXPECT_GT(cv::norm(a.frame.labels, c.frame.labels, cv::NORM_INF), 0.0);
}

TEST(RoomTest, EveryRoomShowsTheTableItsObjectsAndTheFloor) {
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE(seed);
    const SynthScene room = GenerateRoom(seed, {});
    const cv::Mat& labels = room.frame.labels;
    EXPECT_GT(CountLabel(labels, kSupportTableLabel), 10000);
    EXPECT_GT(CountLabel(labels, kFloorLabel), 1000);
    ASSERT_GE(room.objects.size(), 1u);
    for (const ObjectTruth& o : room.objects) {
      EXPECT_GT(o.visible_pixels, 0);
      EXPECT_EQ(CountLabel(labels, o.label), o.visible_pixels);
    }
  }
}

TEST(RoomTest, TheTruthPlaneIsTheSupportTablesTop) {
  const SynthScene room = GenerateRoom(3, {});
  const cv::Mat& depth = room.frame.frame.depth;
  const Intrinsics& k = room.frame.frame.intrinsics;
  int on = 0, table = 0;
  for (int v = 0; v < depth.rows; v += 2) {
    for (int u = 0; u < depth.cols; u += 2) {
      if (room.frame.labels.at<int>(v, u) != kSupportTableLabel) continue;
      const float z = depth.at<float>(v, u);
      const Eigen::Vector3f p((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      ++table;
      // Kinect noise is 1.4 mm at 1 m; the table's edge band is thicker.
      on += std::abs(room.table_normal_camera.dot(p) + room.table_d_camera) <
            0.01f;
    }
  }
  EXPECT_GT(on, 0.9 * table);
}

TEST(RoomTest, ActiveStereoLeavesTheLeftBorderAndShadowsWithoutDepth) {
  RoomOptions options;
  options.sensor = RoomSensor::kActiveStereo;
  const SynthScene room = GenerateRoom(2, options);
  const cv::Mat& depth = room.frame.frame.depth;
  // At 1-3 m the second imager misses f b / z = 10-30 pixels on the left.
  const cv::Mat left = depth(cv::Rect(0, 0, 8, depth.rows));
  EXPECT_EQ(cv::countNonZero(left == left), 0);  // all NaN
  // The Kinect's projector covers the border.
  const SynthScene kinect = GenerateRoom(2, {});
  const cv::Mat k_left =
      kinect.frame.frame.depth(cv::Rect(0, 0, 8, depth.rows));
  EXPECT_GT(cv::countNonZero(k_left == k_left), 0);
}

TEST(RoomTest, WideFramesUseTheWideIntrinsics) {
  RoomOptions options;
  options.sensor = RoomSensor::kActiveStereo;
  options.width = 1280;
  options.height = 720;
  const SynthScene room = GenerateRoom(4, options);
  EXPECT_EQ(room.frame.frame.depth.size(), cv::Size(1280, 720));
  EXPECT_DOUBLE_EQ(room.frame.frame.intrinsics.fx, 920.0);
  EXPECT_GT(CountLabel(room.frame.labels, kSupportTableLabel), 40000);
}

// Each sensor's name round-trips; its own frame is one a generic camera's
// intrinsics are recognised from (core/frame/sensor_model.h): the time of
// flight's nearly square 640x576.
TEST(RoomTest, EachSensorsFrameIsRecognisedAsThatSensor) {
  const std::pair<RoomSensor, SensorKind> sensors[] = {
      {RoomSensor::kKinectV1, SensorKind::kKinectV1},
      {RoomSensor::kActiveStereo, SensorKind::kActiveStereo},
      {RoomSensor::kTimeOfFlight, SensorKind::kTimeOfFlight}};
  for (const auto& [sensor, kind] : sensors) {
    const absl::StatusOr<RoomSensor> parsed =
        ParseRoomSensor(RoomSensorName(sensor));
    ASSERT_TRUE(parsed.ok()) << RoomSensorName(sensor);
    EXPECT_EQ(*parsed, sensor);
    const cv::Size size = SensorFrameSize(sensor);
    EXPECT_EQ(NoiseKind(SensorKind::kGeneric,
                        SensorIntrinsics(sensor, size.width, size.height)),
              kind)
        << RoomSensorName(sensor);
  }
  EXPECT_EQ(SensorFrameSize(RoomSensor::kTimeOfFlight), cv::Size(640, 576));
  EXPECT_NE(ParseRoomSensor("tof").status().message().find("time_of_flight"),
            std::string::npos);
}

TEST(RoomTest, ValidateNamesTheField) {
  RoomOptions options;
  EXPECT_TRUE(Validate(options).ok());
  options.width = 100;
  EXPECT_NE(Validate(options).message().find("RoomOptions.width"),
            std::string::npos);
  options = {};
  options.same_height_probability = 2.0f;
  EXPECT_NE(Validate(options).message().find("same_height_probability"),
            std::string::npos);
  EXPECT_EQ(ParseRoomSensor("kinect").status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ShadowTest, ABoxCastsABandWithoutDepthOnItsLeftAsWideAsTheParallax) {
  // A 10 cm cube whose front is 0.95 m from the camera, in front of a wall
  // 1.5 m away, seen head-on: the second viewpoint 7.5 cm to the right
  // misses f b (1 / 0.95 - 1 / 1.5) = 525 * 0.075 * 0.386 = 15.2 pixels of
  // the wall left of the cube.
  SceneSpec spec;
  spec.table_half_size = {0.01f, 0.01f};  // out of view
  spec.camera_pose = LookAt({0.0f, -1.0f, 5.0f}, {0.0f, 0.0f, 5.0f});
  Primitive cube;
  cube.half_extents = {0.05f, 0.05f, 0.05f};
  cube.pose.translation() = Eigen::Vector3f(0.0f, 0.0f, 5.0f);
  spec.objects.push_back(cube);
  Primitive wall;
  wall.half_extents = {3.0f, 0.01f, 3.0f};
  wall.pose.translation() = Eigen::Vector3f(0.0f, 0.5f + 0.01f, 5.0f);
  spec.background.push_back({wall, kWallLabel});
  NoiseOptions noise;
  noise.enabled = true;
  noise.sigma_per_z2 = 0.0f;
  noise.disparity_step_px = 1e-4f;
  noise.edge_dropout_px = 0;
  noise.color_sigma = 0.0f;
  noise.shadow_baseline_m = 0.075f;
  const SynthScene scene = RenderScene(spec, noise, 1);
  const cv::Mat& depth = scene.frame.frame.depth;
  const int v = 240;
  int cube_left = -1, nan_run = 0;
  for (int u = 0; u < depth.cols; ++u) {
    if (scene.frame.labels.at<int>(v, u) == 20) {
      cube_left = u;
      break;
    }
  }
  ASSERT_GT(cube_left, 20);
  for (int u = cube_left - 1; u >= 0 && std::isnan(depth.at<float>(v, u)); --u)
    ++nan_run;
  EXPECT_NEAR(nan_run, 15, 1);
  // Right of the cube the wall keeps its depth.
  int cube_right = cube_left;
  while (scene.frame.labels.at<int>(v, cube_right + 1) == 20) ++cube_right;
  EXPECT_FALSE(std::isnan(depth.at<float>(v, cube_right + 2)));
}

}  // namespace
}  // namespace fovea::synth
