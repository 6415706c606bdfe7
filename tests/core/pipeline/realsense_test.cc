// The four raw frames of another sensor (shared/data/realsense, via
// FOVEA_REALSENSE_DIR): whole offices, the floor sometimes the largest
// plane. With the shipped models and the default options, as the server
// runs them: the support passes through the marked table pixels, no mask
// covers them or what is off the table, and the marked objects are inside
// masks.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/pipeline/segment.h"
#include "tests/core/testing/models.h"
#include "tools/eval/realsense_frames.h"

namespace fovea {
namespace {

const LoadedModels& Models() { return *testing::ShippedModels(); }

struct FrameRun {
  SupportPlane plane;
  std::vector<cv::Mat> masks;
};

// Whether any mask covers pixel p.
bool Covered(const FrameRun& run, cv::Point p) {
  for (const cv::Mat& m : run.masks) {
    if (m.at<uint8_t>(p) != 0) return true;
  }
  return false;
}

// Checks the support and the table / off-table pixels; returns how many
// of the frame's marked objects are inside a mask.
int CheckFrame(const eval::RealSenseFrame& f, const FrameRun& run,
               bool objects = true) {
  SCOPED_TRACE(f.name);
  const Intrinsics& k = f.frame.intrinsics;
  for (const cv::Point& p : f.table) {
    const float z = f.frame.depth.at<float>(p);
    if (std::isnan(z)) {
      ADD_FAILURE() << "table pixel " << p << " has no depth";
      continue;
    }
    const Eigen::Vector3f q((p.x - k.cx) * z / k.fx, (p.y - k.cy) * z / k.fy,
                            z);
    EXPECT_LT(std::abs(run.plane.Height(q)), 0.02f) << "table pixel " << p;
    EXPECT_FALSE(Covered(run, p)) << "table pixel " << p << " is in a mask";
  }
  for (const cv::Point& p : f.off_table) {
    EXPECT_FALSE(Covered(run, p)) << "off-table pixel " << p << " is in a mask";
  }
  int covered = 0;
  if (!objects) return covered;
  for (const cv::Point& p : f.objects) {
    if (Covered(run, p)) {
      ++covered;
    } else {
      std::printf("%s: object pixel (%d, %d) is in no mask\n", f.name.c_str(),
                  p.x, p.y);
    }
  }
  return covered;
}

class RealSenseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string dir = eval::RealSenseDir();
    if (dir.empty()) GTEST_SKIP() << "FOVEA_REALSENSE_DIR is not set";
    frames_ = eval::LoadRealSenseFrames(dir);
    ASSERT_EQ(frames_.size(), 4u);
    ASSERT_NE(&Models(), nullptr);
  }
  std::vector<eval::RealSenseFrame> frames_;
};

TEST_F(RealSenseTest, IncrementalSegmentationFindsTheTableAndOnlyItsObjects) {
  int objects = 0, covered = 0;
  for (const eval::RealSenseFrame& f : frames_) {
    FrameRun run;
    SegmentSinks sinks;
    sinks.support = [&](const SupportPlane& plane) {
      run.plane = plane;
      return absl::OkStatus();
    };
    sinks.object = [&](SegmentedObject object) {
      run.masks.push_back(std::move(object.mask));
      return absl::OkStatus();
    };
    absl::StatusOr<SegmentSummary> summary = RunSegmentIncremental(
        f.frame, IncrementalOptions{}, &*Models().inc, sinks);
    ASSERT_TRUE(summary.ok()) << f.name << ": " << summary.status();
    covered += CheckFrame(f, run);
    objects += static_cast<int>(f.objects.size());
  }
  // Measured: 23 of the 27. The misses (printed above) are the insides of
  // two white bowls, whose depth runs smoothly over their thin rims into
  // the table (so they are table to geometry), a marker lying flat (1.5 cm
  // high) and a marker's cap cut from its body.
  EXPECT_GE(covered, 23) << "of " << objects << " marked objects";
}

TEST_F(RealSenseTest, DetectsTheTableAsTheSupportWhateverElseIsInView) {
  for (const eval::RealSenseFrame& f : frames_) {
    absl::StatusOr<DetectResult> detect = RunDetect(f.frame, DetectOptions{});
    ASSERT_TRUE(detect.ok()) << f.name << ": " << detect.status();
    FrameRun run{detect->plane, {}};
    CheckFrame(f, run, /*objects=*/false);
    // Every attention point is above the table, in its hull.
    for (const AttentionPoint& p : detect->points) {
      EXPECT_GT(detect->plane.Height(p.point), 0.0f) << f.name;
    }
  }
}

}  // namespace
}  // namespace fovea
