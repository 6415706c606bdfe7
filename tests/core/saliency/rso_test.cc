#include "core/saliency/rso.h"

#include <gtest/gtest.h>

#include "tests/core/saliency/scene_fixture.h"

namespace fovea {
namespace {

TEST(RsoSaliencyTest, AboutOneOnABoxTopAndAboutZeroOnItsSides) {
  const float half_height = 0.06f;
  testing::PreparedScene s =
      testing::Prepare(testing::BoxOnTable({0.05f, 0.05f, half_height}));
  absl::StatusOr<cv::Mat> map =
      ComputeRsoSaliency(s.cloud, s.plane, s.table, {});
  ASSERT_TRUE(map.ok());
  double top_sum = 0, side_sum = 0;
  int top = 0, side = 0;
  for (int v = 0; v < map->rows; ++v) {
    for (int u = 0; u < map->cols; ++u) {
      if (s.truth.frame.labels.at<int>(v, u) < 20) continue;
      if (!s.cloud.HasNormal(u, v)) continue;
      const float h = s.true_height.at<float>(v, u);
      if (h > 2 * half_height - 0.002f) {
        top_sum += map->at<float>(v, u);
        ++top;
      } else if (h > 0.02f && h < 2 * half_height - 0.02f) {
        side_sum += map->at<float>(v, u);
        ++side;
      }
    }
  }
  ASSERT_GT(top, 50);
  ASSERT_GT(side, 50);
  EXPECT_GT(top_sum / top, 0.95);
  EXPECT_LT(side_sum / side, 0.1);
}

TEST(RsoSaliencyTest, TableAndBackgroundAreZero) {
  testing::PreparedScene s =
      testing::Prepare(testing::BoxOnTable({0.05f, 0.05f, 0.05f}));
  absl::StatusOr<cv::Mat> map =
      ComputeRsoSaliency(s.cloud, s.plane, s.table, {});
  ASSERT_TRUE(map.ok());
  for (int v = 0; v < map->rows; ++v) {
    for (int u = 0; u < map->cols; ++u) {
      if (s.truth.frame.labels.at<int>(v, u) < 20) {
        ASSERT_EQ(map->at<float>(v, u), 0.0f) << u << "," << v;
      }
    }
  }
}

TEST(RsoSaliencyTest, PreferringVerticalSurfacesInvertsTheMap) {
  testing::PreparedScene s =
      testing::Prepare(testing::BoxOnTable({0.05f, 0.05f, 0.06f}));
  RsoOptions options;
  options.preferred_angle_deg = 90.0f;
  absl::StatusOr<cv::Mat> map =
      ComputeRsoSaliency(s.cloud, s.plane, s.table, options);
  ASSERT_TRUE(map.ok());
  double max_value = 0;
  cv::Point max_at;
  cv::minMaxLoc(*map, nullptr, &max_value, nullptr, &max_at);
  // The most salient pixel is on a side, well below the top.
  EXPECT_LT(s.true_height.at<float>(max_at), 0.10f);
  EXPECT_GE(s.truth.frame.labels.at<int>(max_at), 20);
}

}  // namespace
}  // namespace fovea
