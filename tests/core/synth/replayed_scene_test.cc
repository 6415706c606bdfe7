#include "core/synth/replayed_scene.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fovea::synth {
namespace {

constexpr Intrinsics kSmall{75.0, 75.0, 39.5, 29.5};

// The depth of pixel row `v` on the table: a plane seen from above and in
// front, nearer at the bottom of the image.
float TableDepth(int v) { return 1.2f - 0.004f * static_cast<float>(v); }

// An 80 x 60 scene: a table (label 1) with a box (label 20, its front face
// 10 cm nearer than the table) at columns 10-29, rows 20-39, a box resting
// on it (label 30, 20 cm nearer) at columns 14-23, rows 24-31, and a can
// (label 40, 8 cm) at columns 50-64, rows 25-40.
LabelledFrame SmallScene() {
  LabelledFrame scene;
  scene.name = "small";
  scene.frame.intrinsics = kSmall;
  scene.frame.depth = cv::Mat(60, 80, CV_32FC1);
  scene.frame.color = cv::Mat(60, 80, CV_8UC3, cv::Scalar(120, 110, 100));
  scene.labels = cv::Mat(60, 80, CV_32SC1, cv::Scalar(1));
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u) {
      float z = TableDepth(v);
      int label = 1;
      cv::Vec3b color(120, 110, 100);
      if (u >= 10 && u < 30 && v >= 20 && v < 40) {
        z -= 0.10f;
        label = 20;
        color = cv::Vec3b(200, 40, 40);
      }
      if (u >= 14 && u < 24 && v >= 24 && v < 32) {
        z = TableDepth(v) - 0.20f;
        label = 30;
        color = cv::Vec3b(40, 200, 40);
      }
      if (u >= 50 && u < 65 && v >= 25 && v < 41) {
        z -= 0.08f;
        label = 40;
        color = cv::Vec3b(40, 40, 200);
      }
      scene.frame.depth.at<float>(v, u) = z;
      scene.labels.at<int>(v, u) = label;
      scene.frame.color.at<cv::Vec3b>(v, u) = color;
    }
  }
  return scene;
}

// Pixels of `frame` labelled as its sequence's object `id`.
int PixelsOf(const SequenceFrame& frame, int id) {
  for (size_t k = 0; k < frame.object_ids.size(); ++k) {
    if (frame.object_ids[k] == id) {
      return cv::countNonZero(frame.frame.labels ==
                              10 * (static_cast<int>(k) + 2));
    }
  }
  return 0;
}

TEST(ReplayedSceneTest, NoiseIsFreshEveryFrameAndSmall) {
  const LabelledFrame scene = SmallScene();
  const Sequence s = ReplayAsSequence(scene, ReplayKind::kNoise, 1, 4);
  ASSERT_EQ(s.frames.size(), 4u);
  for (const SequenceFrame& f : s.frames) {
    EXPECT_EQ(f.object_ids, (std::vector<int>{20, 30, 40}));
    EXPECT_TRUE(f.camera_to_world.isApprox(Eigen::Isometry3f::Identity()));
    // Off the edges the noise is a few mm at 1.1 m: sigma 1.7 mm plus one
    // disparity step of 2.7 mm.
    EXPECT_NEAR(f.frame.frame.depth.at<float>(50, 40), TableDepth(50), 0.012f);
    EXPECT_GT(PixelsOf(f, 20), 150);  // 400 less the box on it and edges
  }
  EXPECT_GT(cv::norm(s.frames[0].frame.frame.color,
                     s.frames[1].frame.frame.color, cv::NORM_L1),
            0.0);
  // Deterministic in the seed.
  const Sequence again = ReplayAsSequence(scene, ReplayKind::kNoise, 1, 4);
  EXPECT_EQ(cv::norm(s.frames[2].frame.frame.color,
                     again.frames[2].frame.frame.color, cv::NORM_INF),
            0.0);
}

// mOSD labels a can's lid apart from its side, and an occluded box's far part
// apart from its near part. The lid touches the side: one truth object. The
// far part lies 6 px from the rest: a truth object of its own.
TEST(ReplayedSceneTest, TouchingPartsAreOneObjectAndSeparatedPartsAreTwo) {
  LabelledFrame scene = SmallScene();
  for (int v = 25; v < 29; ++v) {
    for (int u = 50; u < 65; ++u) scene.labels.at<int>(v, u) = 41;
  }
  for (int v = 45; v < 52; ++v) {
    for (int u = 10; u < 20; ++u) {
      scene.labels.at<int>(v, u) = 21;
      scene.frame.depth.at<float>(v, u) = TableDepth(v) - 0.10f;
    }
  }
  for (const ReplayKind kind : {ReplayKind::kNoise, ReplayKind::kShift}) {
    const Sequence s = ReplayAsSequence(scene, kind, 3, 4);
    for (const SequenceFrame& frame : s.frames) {
      EXPECT_EQ(frame.object_ids, (std::vector<int>{20, 21, 30, 40}));
    }
    // The can's lid and side: about its 15 x 16 pixels (a few dropped).
    EXPECT_GT(PixelsOf(s.frames[0], 40), 200);
    EXPECT_GT(PixelsOf(s.frames[0], 21), 50);
  }
}

TEST(ReplayedSceneTest, ShiftedCameraSeesTheSamePointsWhereThePoseSays) {
  const LabelledFrame scene = SmallScene();
  const Sequence s = ReplayAsSequence(scene, ReplayKind::kShift, 3, 6);
  ASSERT_EQ(s.frames.size(), 6u);
  bool moved = false;
  for (const SequenceFrame& f : s.frames) {
    moved |= f.camera_to_world.translation().norm() > 0.01f;
    // The can's pixels, taken to the world by the pose, are where the
    // scene had them: its centroid within 1 cm.
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    int n = 0;
    for (size_t k = 0; k < f.object_ids.size(); ++k) {
      if (f.object_ids[k] != 40) continue;
      const cv::Mat& labels = f.frame.labels;
      for (int v = 0; v < labels.rows; ++v) {
        for (int u = 0; u < labels.cols; ++u) {
          if (labels.at<int>(v, u) != 10 * (static_cast<int>(k) + 2)) continue;
          const float z = f.frame.frame.depth.at<float>(v, u);
          const Eigen::Vector3f p((u - kSmall.cx) / kSmall.fx * z,
                                  (v - kSmall.cy) / kSmall.fy * z, z);
          sum += f.camera_to_world * p;
          ++n;
        }
      }
    }
    ASSERT_GT(n, 100);
    const Eigen::Vector3f centroid = sum / static_cast<float>(n);
    const float z = TableDepth(33) - 0.08f;
    const Eigen::Vector3f truth((57.0f - kSmall.cx) / kSmall.fx * z,
                                (32.5f - kSmall.cy) / kSmall.fy * z, z);
    EXPECT_LT((centroid - truth).norm(), 0.01f);
  }
  EXPECT_TRUE(moved);
}

TEST(ReplayedSceneTest, ObjectsGoOneAtATimeTheUpperFirstAndTheTableShows) {
  const LabelledFrame scene = SmallScene();
  const Sequence s = ReplayAsSequence(scene, ReplayKind::kRemove, 1, 8);
  ASSERT_EQ(s.frames.size(), 8u);
  // Three objects: the one on top goes at frame 2, then the box under it
  // (reaching 10 cm, above the can's 8) at frame 4; the can stays.
  EXPECT_EQ(s.frames[1].object_ids, (std::vector<int>{20, 30, 40}));
  EXPECT_EQ(s.frames[2].object_ids, (std::vector<int>{20, 40}));
  EXPECT_EQ(s.frames[3].object_ids, (std::vector<int>{20, 40}));
  EXPECT_EQ(s.frames[4].object_ids, (std::vector<int>{40}));
  EXPECT_EQ(s.frames[7].object_ids, (std::vector<int>{40}));
  // Where the boxes stood is table now, at the table's depth.
  const SequenceFrame& last = s.frames[7];
  EXPECT_EQ(last.frame.labels.at<int>(28, 18), 1);
  EXPECT_NEAR(last.frame.frame.depth.at<float>(28, 18), TableDepth(28), 0.01f);
  const cv::Vec3b color = last.frame.frame.color.at<cv::Vec3b>(28, 18);
  EXPECT_NEAR(color[0], 120, 20);  // the table's colour, inpainted
  EXPECT_NEAR(color[1], 110, 20);
  EXPECT_GT(PixelsOf(last, 40), 150);
}

}  // namespace
}  // namespace fovea::synth
