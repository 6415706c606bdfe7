#include "core/eval/segmentation_metrics.h"

#include <gtest/gtest.h>

namespace fovea {
namespace {

// A 10 x 10 scene: object 2 (label 20) in columns 0-3, object 3 (labels 30
// and 31, one object in two parts) in columns 6-9, table (1) between.
cv::Mat Labels() {
  cv::Mat labels(10, 10, CV_32SC1, cv::Scalar(1));
  labels.colRange(0, 4).setTo(20);
  labels.colRange(6, 8).setTo(30);
  labels.colRange(8, 10).setTo(31);
  return labels;
}

cv::Mat Columns(int from, int to) {
  cv::Mat mask(10, 10, CV_8UC1, cv::Scalar(0));
  mask.colRange(from, to).setTo(255);
  return mask;
}

TEST(ScoreSegmentationTest, ThesisFScoresFirstBestAndAll) {
  // Object 2: a perfect mask, then one of columns 0-5 (P 4/6, R 1, F 0.8).
  // Object 3: columns 6-7 (P 1, R 0.5, F 2/3); its second part counts.
  const std::vector<SeededMask> masks = {
      {{1, 5}, Columns(0, 4)},
      {{7, 5}, Columns(6, 8)},
      {{2, 5}, Columns(0, 6)},
  };
  const SegmentationScore s = ScoreSegmentation(Labels(), masks);
  EXPECT_EQ(s.objects, 2);
  EXPECT_EQ(s.objects_with_mask, 2);
  EXPECT_EQ(s.masks, 3);
  EXPECT_EQ(s.false_masks, 0);
  EXPECT_NEAR(s.f_first, (1.0 + 2.0 / 3.0) / 2.0, 1e-9);
  EXPECT_NEAR(s.f_best, (1.0 + 2.0 / 3.0) / 2.0, 1e-9);
  EXPECT_NEAR(s.f_all, ((1.0 + 0.8) / 2.0 + 2.0 / 3.0) / 2.0, 1e-9);
  EXPECT_NEAR(s.recall_all, ((1.0 + 1.0) / 2.0 + 0.5) / 2.0, 1e-9);
}

TEST(ScoreSegmentationTest, SeedsOnTheTableOrOutsideAreFalseMasks) {
  const std::vector<SeededMask> masks = {
      {{5, 5}, Columns(4, 6)},   // table
      {{-1, 3}, Columns(0, 4)},  // outside the image
      {{0, 0}, Columns(0, 2)},   // object 2: P 1, R 0.5
  };
  const SegmentationScore s = ScoreSegmentation(Labels(), masks);
  EXPECT_EQ(s.masks, 3);
  EXPECT_EQ(s.false_masks, 2);
  EXPECT_EQ(s.objects_with_mask, 1);
  EXPECT_NEAR(s.f_all, 2.0 / 3.0, 1e-9);
}

TEST(ScoreSegmentationTest, SmallObjectsAreNotCountedAndNoMasksScoreZero) {
  const SegmentationScore none = ScoreSegmentation(Labels(), {});
  EXPECT_EQ(none.objects, 2);
  EXPECT_EQ(none.objects_with_mask, 0);
  EXPECT_EQ(none.f_all, 0.0);
  // Object 2 has 40 pixels, object 3 has 40: a 41-pixel floor drops both.
  EXPECT_EQ(ScoreSegmentation(Labels(), {}, 41).objects, 0);
}

TEST(WholeSceneFTest, BestSegmentPerObjectAndTableSegmentsIgnored) {
  // Object 2 (columns 0-3): segment 0 covers columns 0-5 (P 4/6, R 1, F
  // 0.8). Object 3 (columns 6-9): segments 1 (6-7) and 2 (8-9) split it;
  // the best is either (P 1, R 0.5, F 2/3).
  cv::Mat segments(10, 10, CV_32SC1, cv::Scalar(-1));
  segments.colRange(0, 6).setTo(0);
  segments.colRange(6, 8).setTo(1);
  segments.colRange(8, 10).setTo(2);
  EXPECT_NEAR(WholeSceneF(Labels(), segments), (0.8 + 2.0 / 3.0) / 2.0, 1e-9);
  // An object no segment touches scores 0.
  cv::Mat only_first(10, 10, CV_32SC1, cv::Scalar(-1));
  only_first.colRange(0, 4).setTo(0);
  EXPECT_NEAR(WholeSceneF(Labels(), only_first), 0.5, 1e-9);
  // A pure table segment changes nothing.
  only_first.colRange(4, 6).setTo(7);
  EXPECT_NEAR(WholeSceneF(Labels(), only_first), 0.5, 1e-9);
}

}  // namespace
}  // namespace fovea
