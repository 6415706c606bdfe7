#include "core/eval/detection_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fovea {
namespace {

// 20x10 scene on the plane z = 1: table (label 1) everywhere, object 2
// (labels 20, 21) in columns 2-6, object 3 (label 30) in columns 12-16,
// rows 2-6. Points are (u, v, 1) in metres-ish units.
struct Scene {
  cv::Mat labels = cv::Mat(10, 20, CV_32SC1, cv::Scalar(1));
  cv::Mat xyz = cv::Mat(10, 20, CV_32FC3);
  Scene() {
    for (int v = 0; v < 10; ++v) {
      for (int u = 0; u < 20; ++u) {
        xyz.at<cv::Vec3f>(v, u) = {static_cast<float>(u), static_cast<float>(v),
                                   1.0f};
      }
    }
    labels(cv::Rect(2, 2, 5, 5)).setTo(20);
    labels(cv::Rect(2, 2, 2, 5)).setTo(21);  // a second part, same object
    labels(cv::Rect(12, 2, 5, 5)).setTo(30);
  }
};

AttentionPoint At(int u, int v) {
  AttentionPoint p;
  p.u = u;
  p.v = v;
  return p;
}

TEST(DetectionMetricsTest, PerfectDetectorScoresHitRatioOneAndDistanceZero) {
  Scene s;
  const DetectionScore score =
      ScoreAttentionPoints({At(4, 4), At(14, 4)}, s.labels, s.xyz);
  EXPECT_EQ(score.objects, 2);
  EXPECT_EQ(score.hits, 2);
  EXPECT_DOUBLE_EQ(score.hit_ratio, 1.0);
  EXPECT_DOUBLE_EQ(score.distance_to_center, 0.0);
  EXPECT_DOUBLE_EQ(score.distance_to_center_thesis, 0.0);
}

TEST(DetectionMetricsTest, OffCentrePointsScoreAboveZero) {
  Scene s;
  const DetectionScore score =
      ScoreAttentionPoints({At(2, 2), At(14, 5)}, s.labels, s.xyz);
  EXPECT_DOUBLE_EQ(score.hit_ratio, 1.0);
  // Corner of object 2 is its farthest point: 1. (14, 5) is 1 from its
  // centre (14, 4), whose farthest point is sqrt(8) away: 1 / sqrt(8).
  EXPECT_NEAR(score.distance_to_center, (1.0 + 1.0 / std::sqrt(8.0)) / 2, 1e-6);
}

TEST(DetectionMetricsTest, TableRepeatsAndSilenceAreMisses) {
  Scene s;
  EXPECT_DOUBLE_EQ(
      ScoreAttentionPoints({At(0, 0), At(4, 4)}, s.labels, s.xyz).hit_ratio,
      0.5);
  // Two points on one object (its two labelled parts count as one object).
  EXPECT_DOUBLE_EQ(
      ScoreAttentionPoints({At(2, 3), At(5, 3)}, s.labels, s.xyz).hit_ratio,
      0.5);
  // Fewer points than objects.
  EXPECT_DOUBLE_EQ(ScoreAttentionPoints({At(4, 4)}, s.labels, s.xyz).hit_ratio,
                   0.5);
  const DetectionScore silent = ScoreAttentionPoints({}, s.labels, s.xyz);
  EXPECT_DOUBLE_EQ(silent.hit_ratio, 0.0);
  EXPECT_DOUBLE_EQ(silent.distance_to_center, 1.0);
}

TEST(DetectionMetricsTest, OneCentredPointAndAMissIsNotAPerfectDistance) {
  Scene s;
  // Object 2 hit at its centre, then a table point: DC = (0 + 1) / 2, while
  // the thesis's ratio, which leaves misses out, is 0.
  const DetectionScore score =
      ScoreAttentionPoints({At(4, 4), At(0, 0)}, s.labels, s.xyz);
  EXPECT_DOUBLE_EQ(score.distance_to_center, 0.5);
  EXPECT_DOUBLE_EQ(score.distance_to_center_thesis, 0.0);
  // A repeat on the same object is a miss for DC too.
  EXPECT_DOUBLE_EQ(ScoreAttentionPoints({At(4, 4), At(4, 4)}, s.labels, s.xyz)
                       .distance_to_center,
                   0.5);
}

TEST(DetectionMetricsTest, OnlyTheFirstKPointsCountForHitRatio) {
  Scene s;
  const DetectionScore score =
      ScoreAttentionPoints({At(4, 4), At(5, 5), At(14, 4)}, s.labels, s.xyz);
  EXPECT_DOUBLE_EQ(score.hit_ratio, 0.5);
  // HR(N): 1/1, 1/2, 2/3, then 2/N.
  EXPECT_DOUBLE_EQ(score.hit_ratio_at[0], 1.0);
  EXPECT_DOUBLE_EQ(score.hit_ratio_at[1], 0.5);
  EXPECT_DOUBLE_EQ(score.hit_ratio_at[2], 2.0 / 3);
  EXPECT_DOUBLE_EQ(score.hit_ratio_at[9], 0.2);
}

TEST(DetectionMetricsTest, PointsOutsideTheImageAreMisses) {
  Scene s;
  EXPECT_DOUBLE_EQ(
      ScoreAttentionPoints({At(-1, 4), At(40, 4)}, s.labels, s.xyz).hit_ratio,
      0.0);
}

}  // namespace
}  // namespace fovea
