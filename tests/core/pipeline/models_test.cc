#include "core/pipeline/models.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "absl/status/status.h"
#include "core/frame/rgbd_frame.h"
#include "core/frame/sensor_model.h"
#include "core/pipeline/segment.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea {
namespace {

using ::testing::HasSubstr;

namespace fs = std::filesystem;

// A fresh folder holding copies of the source tree's three base models.
fs::path BaseModelsCopy(const std::string& name) {
  const char* source = std::getenv("FOVEA_SOURCE_DIR");
  const fs::path shipped = fs::path(source ? source : ".") / "models";
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* file : {kCosModelFile, kEbsModelFile, kIncModelFile}) {
    fs::copy_file(shipped / file, dir / file);
  }
  return dir;
}

RgbdFrame FrameWith(double fx, int width, int height) {
  RgbdFrame frame;
  frame.intrinsics.fx = frame.intrinsics.fy = fx;
  frame.intrinsics.cx = (width - 1) / 2.0;
  frame.intrinsics.cy = (height - 1) / 2.0;
  return frame;
}

constexpr char kStereoDir[] = "active_stereo";
static_assert(kIncFamilies[0] == SensorKind::kActiveStereo &&
              kIncFamilies[1] == SensorKind::kTimeOfFlight);

// Without a family folder every sensor gets the base INC model.
TEST(LoadModelsTest, WithoutAFamilyFolderEverySensorGetsTheBaseModel) {
  const fs::path dir = BaseModelsCopy("models_base");
  const absl::StatusOr<LoadedModels> loaded = LoadModels(dir.string());
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_EQ(loaded->versions.size(), 3u);
  EXPECT_FALSE(loaded->inc_family[0].has_value());
  const SegmentModels view = loaded->View();
  ASSERT_NE(view.inc, nullptr);
  EXPECT_EQ(view.IncFor(SensorKind::kActiveStereo), view.inc);
  EXPECT_EQ(view.IncFor(SensorKind::kKinectV1), view.inc);
}

// The active-stereo folder's model serves the frames of that family: those
// declared so, and undeclared ones whose focal length is not a PrimeSense
// camera's; a Kinect v1 frame, declared or recognised, keeps the base one.
TEST(LoadModelsTest, TheActiveStereoModelServesThatFamilysFramesOnly) {
  const fs::path dir = BaseModelsCopy("models_family");
  fs::create_directories(dir / kStereoDir);
  fs::copy_file(dir / kIncModelFile, dir / kStereoDir / kIncModelFile);
  const absl::StatusOr<LoadedModels> loaded = LoadModels(dir.string());
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_TRUE(loaded->inc_family[0].has_value());
  ASSERT_EQ(loaded->versions.size(), 4u);
  EXPECT_EQ(loaded->versions[3].first, "inc_relations.active_stereo");
  const SegmentModels view = loaded->View();
  const RbfSvm* stereo = &*loaded->inc_family[0];
  ASSERT_NE(stereo, view.inc);

  const RgbdFrame kinect = FrameWith(525.0, 640, 480);
  const RgbdFrame realsense = FrameWith(613.0, 640, 480);
  const RgbdFrame realsense_hd = FrameWith(920.0, 1280, 720);
  SceneOptions generic;
  EXPECT_EQ(view.IncFor(kinect, generic), view.inc);
  EXPECT_EQ(view.IncFor(realsense, generic), stereo);
  EXPECT_EQ(view.IncFor(realsense_hd, generic), stereo);
  SceneOptions declared_kinect;
  declared_kinect.sensor = SensorKind::kKinectV1;
  EXPECT_EQ(view.IncFor(realsense, declared_kinect), view.inc);
  SceneOptions declared_stereo;
  declared_stereo.sensor = SensorKind::kActiveStereo;
  EXPECT_EQ(view.IncFor(kinect, declared_stereo), stereo);
  // No time-of-flight folder: those frames get the base model.
  EXPECT_EQ(view.IncFor(FrameWith(504.0, 640, 576), generic), view.inc);
}

// The time-of-flight folder's model serves that family's frames: declared
// so, or undeclared and nearly square (640x576); the others keep theirs.
TEST(LoadModelsTest, TheTimeOfFlightModelServesThatFamilysFramesOnly) {
  const fs::path dir = BaseModelsCopy("models_tof");
  fs::create_directories(dir / "time_of_flight");
  fs::copy_file(dir / kIncModelFile, dir / "time_of_flight" / kIncModelFile);
  const absl::StatusOr<LoadedModels> loaded = LoadModels(dir.string());
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_FALSE(loaded->inc_family[0].has_value());
  ASSERT_TRUE(loaded->inc_family[1].has_value());
  EXPECT_EQ(loaded->versions.back().first, "inc_relations.time_of_flight");
  const SegmentModels view = loaded->View();
  const RbfSvm* tof = &*loaded->inc_family[1];
  SceneOptions generic;
  EXPECT_EQ(view.IncFor(FrameWith(504.0, 640, 576), generic), tof);
  EXPECT_EQ(view.IncFor(FrameWith(525.0, 640, 480), generic), view.inc);
  EXPECT_EQ(view.IncFor(FrameWith(613.0, 640, 480), generic), view.inc);
  SceneOptions declared;
  declared.sensor = SensorKind::kTimeOfFlight;
  EXPECT_EQ(view.IncFor(FrameWith(613.0, 640, 480), declared), tof);
}

// A family folder without its model, or with a file that is not one, stops
// loading with an error naming the file.
TEST(LoadModelsTest, AFamilyFolderWithoutAValidModelIsAnErrorNamingIt) {
  const fs::path dir = BaseModelsCopy("models_broken_family");
  fs::create_directories(dir / kStereoDir);
  absl::StatusOr<LoadedModels> loaded = LoadModels(dir.string());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(loaded.status().message(),
              HasSubstr("active_stereo/inc_relations.txt"));
  EXPECT_THAT(loaded.status().message(), HasSubstr("--sensor active_stereo"));

  std::ofstream(dir / kStereoDir / kIncModelFile) << "not a model\n";
  loaded = LoadModels(dir.string());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(loaded.status().message(),
              HasSubstr("active_stereo/inc_relations.txt"));
}

}  // namespace
}  // namespace fovea
