#include "core/scene/workspace.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

// A fronto-parallel wall whose depth grows 1 cm per column from 0.5 m.
OrganizedCloud Ramp() {
  RgbdFrame frame;
  frame.intrinsics = {100.0, 100.0, 49.5, 9.5};
  frame.color = cv::Mat(20, 100, CV_8UC3, cv::Scalar(0, 0, 0));
  frame.depth = cv::Mat(20, 100, CV_32FC1);
  for (int v = 0; v < 20; ++v) {
    for (int u = 0; u < 100; ++u)
      frame.depth.at<float>(v, u) = 0.5f + 0.01f * u;
  }
  return BackProject(frame);
}

int Valid(const OrganizedCloud& cloud) {
  int n = 0;
  for (int v = 0; v < cloud.height(); ++v) {
    for (int u = 0; u < cloud.width(); ++u) n += cloud.HasPoint(u, v);
  }
  return n;
}

const SensorModel kSensor =
    SensorModelFor(SensorKind::kActiveStereo, {100.0, 100.0, 49.5, 9.5});

TEST(WorkspaceTest, DepthRangeKeepsOnlyTheColumnsInside) {
  OrganizedCloud cloud = Ramp();
  Workspace w;
  w.min_depth_m = 0.7f;    // column 20
  w.max_depth_m = 1.095f;  // column 59
  const int removed = ApplyWorkspace(w, kSensor, cloud);
  EXPECT_EQ(Valid(cloud), 20 * 40);
  EXPECT_EQ(removed, 20 * 60);
  EXPECT_FALSE(cloud.HasPoint(19, 5));
  EXPECT_TRUE(cloud.HasPoint(20, 5));
  EXPECT_TRUE(cloud.HasPoint(59, 5));
  EXPECT_FALSE(cloud.HasPoint(60, 5));
}

TEST(WorkspaceTest, UnsetRangeIsTheSensorsRange) {
  OrganizedCloud cloud = Ramp();
  SensorModel sensor = kSensor;
  sensor.min_range_m = 0.2f;
  sensor.max_range_m = 1.0f;  // columns 0..50
  ApplyWorkspace(Workspace{}, sensor, cloud);
  EXPECT_TRUE(cloud.HasPoint(50, 0));
  EXPECT_FALSE(cloud.HasPoint(51, 0));
}

TEST(WorkspaceTest, BoxKeepsThePointsInsideIt) {
  OrganizedCloud cloud = Ramp();
  Workspace w;
  w.box = Workspace::Box{{-10.0f, -10.0f, 0.0f}, {0.0f, 10.0f, 10.0f}};
  ApplyWorkspace(w, kSensor, cloud);  // x <= 0: columns up to the centre
  EXPECT_TRUE(cloud.HasPoint(49, 3));
  EXPECT_FALSE(cloud.HasPoint(50, 3));
}

TEST(WorkspaceTest, ValidateNamesTheField) {
  Workspace w;
  EXPECT_TRUE(Validate(w).ok());
  w.max_depth_m = std::nanf("");
  EXPECT_NE(Validate(w).message().find("workspace.max_depth_m"),
            std::string::npos);
  w.max_depth_m = 1.0f;
  w.min_depth_m = 2.0f;
  EXPECT_NE(Validate(w).message().find("max_depth_m must exceed"),
            std::string::npos);
  w = {};
  w.box = Workspace::Box{{0.0f, 0.0f, 1.0f}, {1.0f, 1.0f, 1.0f}};  // flat in z
  EXPECT_EQ(Validate(w).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(Validate(w).message().find("workspace.box is empty: max.z"),
            std::string::npos)
      << Validate(w);
}

}  // namespace
}  // namespace fovea
