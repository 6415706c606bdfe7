#include "core/eval/uois_metrics.h"

#include <gtest/gtest.h>

namespace fovea {
namespace {

// A 100 x 100 scene: object 1 is the square [10, 30)^2, object 2 the
// rectangle [50, 90) x [10, 30) (wide 40, tall 20).
cv::Mat TwoObjects() {
  cv::Mat objects(100, 100, CV_32SC1, cv::Scalar(0));
  objects(cv::Rect(10, 10, 20, 20)).setTo(1);
  objects(cv::Rect(50, 10, 40, 20)).setTo(2);
  return objects;
}

cv::Mat NoSegments() { return cv::Mat(100, 100, CV_32SC1, cv::Scalar(-1)); }

TEST(UoisMetricsTest, PerfectSegmentsScoreOneEverywhere) {
  const cv::Mat objects = TwoObjects();
  cv::Mat segments = NoSegments();
  segments.setTo(7, objects == 1);  // ids need not follow the objects'
  segments.setTo(3, objects == 2);
  const UoisScore s = ScoreUois(objects, segments);
  EXPECT_DOUBLE_EQ(s.overlap_p, 1.0);
  EXPECT_DOUBLE_EQ(s.overlap_r, 1.0);
  EXPECT_DOUBLE_EQ(s.boundary_f, 1.0);
  EXPECT_DOUBLE_EQ(s.objects_075, 1.0);
  EXPECT_EQ(s.objects, 2);
  EXPECT_EQ(s.segments, 2);
}

TEST(UoisMetricsTest, OneSegmentOverBothObjectsMatchesOnlyOne) {
  // One segment covering both objects (400 + 800 pixels): it matches the
  // larger object (F 2*800/(800+1200) = 0.8); P = 800/1200, R = 800/1200.
  const cv::Mat objects = TwoObjects();
  cv::Mat segments = NoSegments();
  segments.setTo(0, objects > 0);
  const UoisScore s = ScoreUois(objects, segments);
  EXPECT_NEAR(s.overlap_p, 800.0 / 1200.0, 1e-12);
  EXPECT_NEAR(s.overlap_r, 800.0 / 1200.0, 1e-12);
  EXPECT_NEAR(s.objects_075, 0.5, 1e-12);  // 0.8 > 0.75; the other has none
}

TEST(UoisMetricsTest, AnUnmatchedSegmentLowersPrecisionOnly) {
  const cv::Mat objects = TwoObjects();
  cv::Mat segments = NoSegments();
  segments.setTo(0, objects == 1);
  segments.setTo(1, objects == 2);
  segments(cv::Rect(10, 60, 30, 30)).setTo(2);  // 900 pixels on nothing
  const UoisScore s = ScoreUois(objects, segments);
  EXPECT_NEAR(s.overlap_p, 1200.0 / 2100.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.overlap_r, 1.0);
  EXPECT_LT(s.boundary_p, 1.0);
  EXPECT_DOUBLE_EQ(s.boundary_r, 1.0);
  EXPECT_DOUBLE_EQ(s.objects_075, 1.0);
}

TEST(UoisMetricsTest, HalfAnObjectHasRecallAHalfAndFailsTheThreshold) {
  const cv::Mat objects = TwoObjects();
  cv::Mat segments = NoSegments();
  segments(cv::Rect(10, 10, 10, 20)).setTo(0);  // left half of object 1
  segments.setTo(1, objects == 2);
  const UoisScore s = ScoreUois(objects, segments);
  EXPECT_DOUBLE_EQ(s.overlap_p, 1.0);
  EXPECT_NEAR(s.overlap_r, 1000.0 / 1200.0, 1e-12);
  // Object 1's F is 2 * 200 / 600 = 0.667 < 0.75.
  EXPECT_NEAR(s.objects_075, 0.5, 1e-12);
}

TEST(UoisMetricsTest, BoundaryOffByOnePixelIsWithinTheTolerance) {
  // 100 x 100: tolerance ceil(0.003 * 141.4) = 1 pixel.
  EXPECT_EQ(BoundaryTolerancePx({100, 100}), 1);
  EXPECT_EQ(BoundaryTolerancePx({640, 480}), 3);
  const cv::Mat objects = TwoObjects();
  cv::Mat segments = NoSegments();
  segments(cv::Rect(11, 10, 20, 20)).setTo(0);  // shifted right by one
  segments.setTo(1, objects == 2);
  const UoisScore s = ScoreUois(objects, segments);
  EXPECT_DOUBLE_EQ(s.boundary_p, 1.0);
  EXPECT_DOUBLE_EQ(s.boundary_r, 1.0);
  EXPECT_LT(s.overlap_f, 1.0);
}

TEST(UoisMetricsTest, NoSegmentsScoresNoRecall) {
  const UoisScore s = ScoreUois(TwoObjects(), NoSegments());
  EXPECT_DOUBLE_EQ(s.overlap_r, 0.0);
  EXPECT_DOUBLE_EQ(s.overlap_f, 0.0);
  EXPECT_DOUBLE_EQ(s.objects_075, 0.0);
}

TEST(UoisMetricsTest, SmallObjectsAreLeftOut) {
  cv::Mat objects = TwoObjects();
  objects(cv::Rect(80, 80, 3, 3)).setTo(5);  // 9 pixels
  cv::Mat segments = NoSegments();
  segments.setTo(0, objects == 1);
  segments.setTo(1, objects == 2);
  EXPECT_EQ(ScoreUois(objects, segments, 50).objects, 2);
  EXPECT_DOUBLE_EQ(ScoreUois(objects, segments, 50).overlap_r, 1.0);
  EXPECT_EQ(ScoreUois(objects, segments, 1).objects, 3);
}

}  // namespace
}  // namespace fovea
