// Detect on the real OSD scenes. Skips when FOVEA_OSD_DIR is unset or does
// not hold the data (shared/data/README.md).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/frame/frame_decode.h"
#include "core/frame/osd_pcd.h"
#include "core/pipeline/detect.h"
#include "tests/core/testing/osd.h"

namespace fovea {
namespace {

using testing::OsdDir;

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(DetectOsdTest, RunsOnEveryLearnSceneWithPointsOnObjects) {
  const std::string dir = OsdDir();
  if (dir.empty()) GTEST_SKIP() << "FOVEA_OSD_DIR is unset or has no learn/";
  absl::StatusOr<std::vector<std::string>> files = ListPcdFiles(dir + "/learn");
  ASSERT_TRUE(files.ok()) << files.status();
  ASSERT_EQ(files->size(), 45u);
  int first_on_object = 0;
  for (const std::string& path : *files) {
    absl::StatusOr<LabelledFrame> scene = LoadOsdPcd(path);
    ASSERT_TRUE(scene.ok()) << scene.status();
    absl::StatusOr<DetectResult> result = RunDetect(scene->frame, {});
    ASSERT_TRUE(result.ok()) << path << ": " << result.status();
    ASSERT_FALSE(result->points.empty()) << path;
    const AttentionPoint& p = result->points[0];
    first_on_object += scene->labels.at<int>(p.v, p.u) >= 20;
  }
  // The first point lands on an object in (nearly) every scene.
  EXPECT_GE(first_on_object, 43);
}

TEST(DetectOsdTest, PngFrameGivesThePointsOfItsPcd) {
  const std::string dir = OsdDir();
  if (dir.empty()) GTEST_SKIP() << "FOVEA_OSD_DIR is unset or has no learn/";
  absl::StatusOr<LabelledFrame> pcd = LoadOsdPcd(dir + "/learn/learn6.pcd");
  ASSERT_TRUE(pcd.ok()) << pcd.status();
  const std::string color = ReadFile(dir + "/frames/learn6_color.png");
  const std::string depth = ReadFile(dir + "/frames/learn6_depth_mm.png");
  RawFrame raw;
  raw.color.compressed = color;
  raw.depth.compressed = depth;
  raw.intrinsics = kKinectV1Intrinsics;
  raw.depth_scale = 0.001;
  absl::StatusOr<RgbdFrame> frame = DecodeFrame(raw, FrameLimits{});
  ASSERT_TRUE(frame.ok()) << frame.status();

  DetectOptions options;
  options.max_points = 3;
  absl::StatusOr<DetectResult> from_pcd = RunDetect(pcd->frame, options);
  absl::StatusOr<DetectResult> from_png = RunDetect(*frame, options);
  ASSERT_TRUE(from_pcd.ok() && from_png.ok());
  ASSERT_GE(from_pcd->points.size(), 2u);
  ASSERT_EQ(from_png->points.size(), from_pcd->points.size());
  // The two objects' points agree within a few pixels; the uncropped frame
  // (floor and wall visible) must not change what is found.
  for (size_t i = 0; i < 2; ++i) {
    const AttentionPoint& a = from_pcd->points[i];
    const AttentionPoint& b = from_png->points[i];
    EXPECT_LE(std::hypot(a.u - b.u, a.v - b.v), 4.0)
        << "point " << i << ": pcd (" << a.u << ", " << a.v << ") png (" << b.u
        << ", " << b.v << ")";
  }
  // The uncropped frame shows the floor and a wall rising at the table's
  // far edge (label 0 in the cropped PCD): no point may land there.
  options.max_points = 10;
  absl::StatusOr<DetectResult> all = RunDetect(*frame, options);
  ASSERT_TRUE(all.ok());
  for (const AttentionPoint& p : all->points) {
    EXPECT_NE(pcd->labels.at<int>(p.v, p.u), 0)
        << "point at (" << p.u << ", " << p.v << ") is off the table";
  }
  // And the support planes agree.
  EXPECT_GT(from_pcd->plane.normal.dot(from_png->plane.normal), 0.9995f);
  EXPECT_NEAR(from_pcd->plane.d, from_png->plane.d, 0.01f);
}

}  // namespace
}  // namespace fovea
