#include "core/saliency/rso.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "tests/core/saliency/scene_fixture.h"

namespace fovea {
namespace {

float Median(std::vector<float> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(RsoSaliencyTest, AboutOneOnABoxTopAndAboutZeroOnItsSides) {
  const float half_height = 0.06f;
  testing::PreparedScene s =
      testing::Prepare(testing::BoxOnTable({0.05f, 0.05f, half_height}));
  absl::StatusOr<cv::Mat> map =
      ComputeRsoSaliency(s.cloud, s.plane, s.table, {});
  ASSERT_TRUE(map.ok());
  std::vector<float> top, side;
  for (int v = 0; v < map->rows; ++v) {
    for (int u = 0; u < map->cols; ++u) {
      if (s.truth.frame.labels.at<int>(v, u) < 20) continue;
      if (!s.cloud.HasNormal(u, v)) continue;
      const float h = s.true_height.at<float>(v, u);
      if (h > 2 * half_height - 0.002f) {
        top.push_back(map->at<float>(v, u));
      } else if (h > 0.02f && h < 2 * half_height - 0.02f) {
        side.push_back(map->at<float>(v, u));
      }
    }
  }
  ASSERT_GT(top.size(), 50u);
  ASSERT_GT(side.size(), 50u);
  // Medians: the face, not the few pixels whose smoothing window straddles
  // the top's edge.
  EXPECT_GT(Median(top), 0.95f);
  EXPECT_LT(Median(side), 0.1f);
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
