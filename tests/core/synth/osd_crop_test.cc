#include "core/synth/osd_crop.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/frame/osd_pcd.h"

namespace fovea::synth {
namespace {

TEST(CroppedPileTest, ObjectsKeepEveryPixelTheTableBehindThePileIsGone) {
  const StackedPile whole = GenerateStackedPile(3, RoomSensor::kKinectV1);
  const StackedPile cropped = GenerateCroppedPile(3, RoomSensor::kKinectV1);
  EXPECT_EQ(cropped.scene.frame.name, "stack-crop-3");
  const cv::Mat& before = whole.scene.frame.labels;
  const cv::Mat& after = cropped.scene.frame.labels;
  int object_pixels = 0, table_before = 0, table_after = 0, background = 0;
  for (int v = 0; v < before.rows; ++v) {
    for (int u = 0; u < before.cols; ++u) {
      const int label = before.at<int>(v, u);
      if (ObjectId(label) != 0) {
        ++object_pixels;
        // Every object pixel as it was: label and depth.
        ASSERT_EQ(after.at<int>(v, u), label);
        const float z0 = whole.scene.frame.frame.depth.at<float>(v, u);
        const float z1 = cropped.scene.frame.frame.depth.at<float>(v, u);
        ASSERT_TRUE(z0 == z1 || (std::isnan(z0) && std::isnan(z1)));
      }
      table_before += label == kSupportTableLabel;
      table_after += after.at<int>(v, u) == kSupportTableLabel;
      background += after.at<int>(v, u) > kSupportTableLabel &&
                    ObjectId(after.at<int>(v, u)) == 0;
    }
  }
  EXPECT_GT(object_pixels, 10000);
  // Floor and wall are cropped whole, the table behind the pile's middle.
  EXPECT_EQ(background, 0);
  EXPECT_GT(table_after, 0);
  EXPECT_LT(table_after, 0.8 * table_before);
}

TEST(CropLikeOsdTest, CutsTheTableBeyondFarYOnly) {
  SceneSpec spec;
  spec.camera_pose = LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  NoiseOptions noise;
  noise.enabled = false;
  SynthScene scene = RenderScene(spec, noise, 1);
  CropLikeOsd(spec, 0.0f, scene);
  const LabelledFrame& f = scene.frame;
  const Intrinsics& k = f.frame.intrinsics;
  int kept = 0;
  for (int v = 0; v < f.labels.rows; ++v) {
    for (int u = 0; u < f.labels.cols; ++u) {
      const float z = f.frame.depth.at<float>(v, u);
      if (std::isnan(z)) continue;
      ++kept;
      const Eigen::Vector3f camera(static_cast<float>((u - k.cx) / k.fx) * z,
                                   static_cast<float>((v - k.cy) / k.fy) * z,
                                   z);
      EXPECT_LE((spec.camera_pose * camera).y(), 1e-4f);
    }
  }
  EXPECT_GT(kept, 1000);
}

}  // namespace
}  // namespace fovea::synth
