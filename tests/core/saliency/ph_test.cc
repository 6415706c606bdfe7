#include "core/saliency/ph.h"

#include <gtest/gtest.h>

namespace fovea {
namespace {

// A 4x3 table scene: row 0 table (height 0; marked candidate so that PH
// itself must give it 0), rows 1-2 two objects 0.1 m and 0.2 m tall.
TableScene TinyScene() {
  TableScene scene;
  scene.height = (cv::Mat_<float>(3, 4) << 0.0f, 0.0f, 0.0f, 0.0f,  //
                  0.05f, 0.1f, 0.1f, 0.05f,                         //
                  0.1f, 0.2f, 0.15f, 0.05f);
  scene.candidate = (cv::Mat_<uint8_t>(3, 4) << 255, 255, 255, 255,  //
                     255, 255, 255, 255,                             //
                     255, 255, 255, 255);
  scene.candidate_count = 12;
  return scene;
}

TEST(PhSaliencyTest, ZeroOnTheTableOneAtTheTopOfTheTallestObject) {
  absl::StatusOr<cv::Mat> map = ComputePhSaliency(TinyScene(), {});
  ASSERT_TRUE(map.ok());
  for (int u = 0; u < 4; ++u) EXPECT_EQ(map->at<float>(0, u), 0.0f);
  EXPECT_FLOAT_EQ(map->at<float>(2, 1), 1.0f);
  // Monotone in height below the top: 0.05 < 0.1 < 0.15 < 0.2.
  EXPECT_LT(map->at<float>(1, 0), map->at<float>(1, 1));
  EXPECT_LT(map->at<float>(1, 1), map->at<float>(2, 2));
  EXPECT_LT(map->at<float>(2, 2), map->at<float>(2, 1));
  // The parabola of eq. 2.3: s(h) = 1 - (1 - h/H)^2 at h = H/2 is 0.75.
  EXPECT_NEAR(map->at<float>(1, 1), 0.75f, 1e-6f);
}

TEST(PhSaliencyTest, TopOffsetMovesThePeakDown) {
  PhOptions options;
  options.top_offset_fraction = 0.5f;  // prefer 0.1 m
  absl::StatusOr<cv::Mat> map = ComputePhSaliency(TinyScene(), options);
  ASSERT_TRUE(map.ok());
  EXPECT_FLOAT_EQ(map->at<float>(1, 1), 1.0f);
  EXPECT_LT(map->at<float>(2, 1), 0.1f);  // 0.2 m is as far from the peak as 0
}

TEST(PhSaliencyTest, EmptySceneIsAllZero) {
  TableScene scene = TinyScene();
  scene.candidate.setTo(0);
  scene.candidate_count = 0;
  absl::StatusOr<cv::Mat> map = ComputePhSaliency(scene, {});
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(cv::countNonZero(*map), 0);
}

TEST(PhSaliencyTest, ValidateNamesTheField) {
  PhOptions options;
  options.top_offset_fraction = 1.5f;
  const absl::Status s = ComputePhSaliency(TinyScene(), options).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("ph.top_offset_fraction"), std::string::npos);
}

}  // namespace
}  // namespace fovea
