// The scorecard's figures on scenes whose right answer is plain, and its
// comparison with a baseline.

#include "tools/eval/scorecard.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace fovea::eval {
namespace {

// 64 x 48 labels: table (1) everywhere, object 2 (label 20) a 20 x 20
// square at (5, 5), object 3 (labels 30 and 31: two parts of one object) a
// 20 x 20 square at (35, 5) split down its middle.
cv::Mat TwoObjects() {
  cv::Mat labels(48, 64, CV_32SC1, cv::Scalar(1));
  labels(cv::Rect(5, 5, 20, 20)).setTo(20);
  labels(cv::Rect(35, 5, 10, 20)).setTo(30);
  labels(cv::Rect(45, 5, 10, 20)).setTo(31);
  return labels;
}

cv::Mat NoSegments(const cv::Mat& labels) {
  return cv::Mat(labels.size(), CV_32SC1, cv::Scalar(-1));
}

TEST(ScoreSegmentsTest, OneMaskPerObjectIsOneMaskPerObject) {
  const cv::Mat labels = TwoObjects();
  cv::Mat segments = NoSegments(labels);
  segments(cv::Rect(5, 5, 20, 20)).setTo(0);
  segments(cv::Rect(35, 5, 20, 20)).setTo(1);  // both parts: one object
  const SegmentFigures f = ScoreSegments(labels, segments);
  EXPECT_EQ(f.objects, 2);
  EXPECT_EQ(f.found, 2);
  EXPECT_TRUE(f.missed.empty());
  EXPECT_EQ(f.object_masks, 2);
  EXPECT_EQ(f.objects_with_masks, 2);
  EXPECT_EQ(f.false_objects, 0);
  EXPECT_DOUBLE_EQ(f.uois.overlap_f, 1.0);
}

TEST(ScoreSegmentsTest, AnObjectInPiecesCountsEveryPiece) {
  const cv::Mat labels = TwoObjects();
  cv::Mat segments = NoSegments(labels);
  // Object 2 in three pieces (a body and two small "handles"), object 3
  // whole.
  segments(cv::Rect(5, 5, 14, 20)).setTo(0);
  segments(cv::Rect(19, 5, 6, 10)).setTo(1);
  segments(cv::Rect(19, 15, 6, 10)).setTo(2);
  segments(cv::Rect(35, 5, 20, 20)).setTo(3);
  const SegmentFigures f = ScoreSegments(labels, segments);
  EXPECT_EQ(f.object_masks, 4);
  EXPECT_EQ(f.objects_with_masks, 2);  // 2 masks per object
  EXPECT_EQ(f.found, 2);               // the body alone still has F >= 0.5
  EXPECT_LT(f.uois.overlap_f, 1.0);
}

TEST(ScoreSegmentsTest, AMaskOnTheTableIsAFalseObjectAndAMissedObjectIsLost) {
  const cv::Mat labels = TwoObjects();
  cv::Mat segments = NoSegments(labels);
  segments(cv::Rect(5, 30, 20, 10)).setTo(0);  // table only
  segments(cv::Rect(35, 5, 20, 20)).setTo(1);
  const SegmentFigures f = ScoreSegments(labels, segments);
  EXPECT_EQ(f.false_objects, 1);
  EXPECT_EQ(f.found, 1);
  EXPECT_EQ(f.missed, std::vector<int>{2});  // object 2 (label 20)
  EXPECT_EQ(f.object_masks, 1);
  // A mask taking two whole objects matches neither one to one.
  cv::Mat both = NoSegments(labels);
  both(cv::Rect(5, 5, 50, 20)).setTo(0);
  const SegmentFigures g = ScoreSegments(labels, both);
  EXPECT_EQ(g.object_masks, 1);
  EXPECT_EQ(g.objects_with_masks, 1);
  EXPECT_LT(g.uois.overlap_f, 0.8);
}

ScorecardRow Row(const std::string& set, const std::string& kind,
                 double overlap_f, double masks_per_object) {
  ScorecardRow r;
  r.set = set;
  r.method = "inc";
  r.kind = kind;
  r.scenes = 3;
  r.overlap_f = overlap_f;
  r.masks_per_object = masks_per_object;
  return r;
}

TEST(CompareScorecardTest, AFallBeyondTheMarginIsReportedARiseIsNot) {
  const std::vector<ScorecardRow> baseline = {Row("osd", "boxes", 0.95, 1.1),
                                              Row("osd", "stacked", 0.90, 1.2),
                                              Row("rooms", "all", 0.8, 1.0)};
  const std::string json = ScorecardJson(baseline);
  // Same figures: nothing fell.
  absl::StatusOr<std::vector<std::string>> same =
      CompareScorecard(baseline, json);
  ASSERT_TRUE(same.ok()) << same.status();
  EXPECT_TRUE(same->empty());
  // Boxes F falls by more than the margin; stacked rises; masks per object
  // on stacked rise by more than theirs; rooms are not run.
  const std::vector<ScorecardRow> now = {
      Row("osd", "boxes", 0.95 - 2 * kScoreMargin, 1.1),
      Row("osd", "stacked", 0.99, 1.2 + 2 * kCountMargin)};
  absl::StatusOr<std::vector<std::string>> falls = CompareScorecard(now, json);
  ASSERT_TRUE(falls.ok()) << falls.status();
  ASSERT_EQ(falls->size(), 2u);
  EXPECT_NE((*falls)[0].find("osd/inc/boxes overlap_f"), std::string::npos);
  EXPECT_NE((*falls)[1].find("osd/inc/stacked masks_per_object"),
            std::string::npos);
  // Within the margin is not a fall.
  const std::vector<ScorecardRow> close = {
      Row("osd", "boxes", 0.95 - kScoreMargin / 2, 1.1 + kCountMargin / 2)};
  EXPECT_TRUE(CompareScorecard(close, json)->empty());
}

TEST(CompareScorecardTest, ABaselineThatDoesNotParseIsAnError) {
  EXPECT_EQ(CompareScorecard({}, "{not json").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CompareScorecard({}, "{\"rows\": 3}").status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ScorecardMarkdownTest, OneLinePerRowUnderAHeader) {
  const std::string md = ScorecardMarkdown(
      {Row("osd", "boxes", 0.95, 1.1), Row("piles", "pile", 0.8, 1.3)});
  EXPECT_NE(md.find("| osd | inc | boxes | 3 |"), std::string::npos);
  EXPECT_NE(md.find("| piles | inc | pile | 3 |"), std::string::npos);
  EXPECT_EQ(std::count(md.begin(), md.end(), '\n'), 4);
}

}  // namespace
}  // namespace fovea::eval

namespace fovea::eval {
namespace {

RealismComparison Realism(const std::string& synthetic, double ks) {
  RealismComparison c;
  c.sensor = "kinect_v1";
  c.real = "osd";
  c.synthetic = synthetic;
  RealismDistance a, b;
  a.statistic = "plane_noise";
  a.ks = ks;
  b.statistic = "normal_angle";
  b.ks = ks;
  c.rows = {a, b};
  return c;
}

TEST(CompareRealismRowsTest, SyntheticFramesMovingAwayFromRealOnesIsAFall) {
  const std::string json =
      ScorecardJson({Row("osd", "boxes", 0.95, 1.1)},
                    {Realism("piles", 0.30), Realism("rooms", 0.40)});
  EXPECT_NE(json.find("\"realism\""), std::string::npos);
  // The same, and closer to the real frames: no fall.
  EXPECT_TRUE(CompareRealismRows({Realism("piles", 0.30)}, json)->empty());
  EXPECT_TRUE(CompareRealismRows({Realism("piles", 0.10)}, json)->empty());
  // Piles farther by more than the margin; rooms within it.
  absl::StatusOr<std::vector<std::string>> falls =
      CompareRealismRows({Realism("piles", 0.30 + 2 * kRealismMargin),
                          Realism("rooms", 0.40 + kRealismMargin / 2)},
                         json);
  ASSERT_TRUE(falls.ok()) << falls.status();
  ASSERT_EQ(falls->size(), 1u);
  EXPECT_NE((*falls)[0].find("realism/osd/piles mean_ks"), std::string::npos);
  // A baseline without realism rows compares none.
  EXPECT_TRUE(CompareRealismRows({Realism("piles", 0.9)},
                                 ScorecardJson({Row("osd", "boxes", 0.9, 1.0)}))
                  ->empty());
  EXPECT_EQ(CompareRealismRows({}, "{not json").status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea::eval
