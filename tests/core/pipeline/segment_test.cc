#include "core/pipeline/segment.h"

#include <gtest/gtest.h>

#include <set>

#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

// The argued SVM of cos_test: faces of one box join, the other box not.
LinearSvm ArguedSvm() {
  return LinearSvm("cos", CosFeatureNames(), {1.0, -3.0}, 0.0, "test");
}

struct SegmentRun {
  absl::StatusOr<SegmentSummary> summary;
  std::vector<AttentionPoint> points;
  std::vector<SegmentedObject> objects;
  int points_calls = 0;
};

SegmentRun RunOn(const synth::SynthScene& scene, const SegmentOptions& options,
                 const InterruptCheck& interrupt = {}) {
  static const LinearSvm svm = ArguedSvm();
  SegmentModels models;
  models.cos = &svm;
  SegmentRun run;
  SegmentSinks sinks;
  sinks.points = [&](const std::vector<AttentionPoint>& points) {
    EXPECT_TRUE(run.objects.empty()) << "points come before objects";
    run.points = points;
    ++run.points_calls;
    return absl::OkStatus();
  };
  sinks.object = [&](SegmentedObject object) {
    run.objects.push_back(std::move(object));
    return absl::OkStatus();
  };
  run.summary =
      RunSegment(scene.frame.frame, options, models, sinks, interrupt);
  return run;
}

TEST(RunSegmentTest, GivenSeedsAreKeptInOrderAndEachGivesItsObject) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  const cv::Point blue = testing::CentreOfLabel(scene.frame.labels, 30);
  const cv::Point red = testing::CentreOfLabel(scene.frame.labels, 20);
  SegmentOptions options;
  options.seeds = {blue, red, {320, 470} /* table */};
  const SegmentRun run = RunOn(scene, options);
  ASSERT_TRUE(run.summary.ok()) << run.summary.status();
  EXPECT_EQ(run.points_calls, 1);
  ASSERT_EQ(run.points.size(), 3u);
  EXPECT_EQ(run.points[0].u, blue.x);
  EXPECT_EQ(run.points[1].u, red.x);
  ASSERT_EQ(run.objects.size(), 2u);  // the table seed yields nothing
  EXPECT_EQ(run.objects[0].index, 0);
  EXPECT_EQ(run.objects[0].seed.u, blue.x);
  EXPECT_EQ(run.objects[1].seed.u, red.x);
  EXPECT_EQ(run.summary->objects, 2);
  EXPECT_EQ(run.summary->stop, SegmentStop::kDone);
  // The red box: 8 cm wide, 10 cm tall, 8 cm deep; its centroid is about
  // 0.75 * sqrt(2) = 1.06 m away, a little left of the image centre.
  const SegmentedObject& r = run.objects[1];
  EXPECT_NEAR(r.extent.x(), 0.08, 0.015);
  EXPECT_LT(r.centroid.x(), 0.0);
  EXPECT_NEAR(r.centroid.z(), 1.0, 0.1);
  EXPECT_EQ(r.area, cv::countNonZero(r.mask));
  EXPECT_TRUE(r.box.contains(red));
  EXPECT_GE(r.seconds_since_start, run.objects[0].seconds_since_start);
  EXPECT_GT(run.summary->scene_coverage, 0.8);
  EXPECT_LE(run.summary->scene_coverage, 1.0);
}

TEST(RunSegmentTest, StopsAtMaxObjects) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  SegmentOptions options;
  options.seeds = {testing::CentreOfLabel(scene.frame.labels, 20),
                   testing::CentreOfLabel(scene.frame.labels, 30)};
  options.max_objects = 1;
  const SegmentRun run = RunOn(scene, options);
  ASSERT_TRUE(run.summary.ok()) << run.summary.status();
  EXPECT_EQ(run.objects.size(), 1u);
  EXPECT_EQ(run.summary->stop, SegmentStop::kMaxObjects);
}

TEST(RunSegmentTest, CoverSceneSeedsTheBoxNoSeedHeld) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  const cv::Point red = testing::CentreOfLabel(scene.frame.labels, 20);
  SegmentOptions options;
  options.seeds = {red};
  // Given seeds: just their objects.
  const SegmentRun given = RunOn(scene, options);
  ASSERT_TRUE(given.summary.ok()) << given.summary.status();
  ASSERT_EQ(given.objects.size(), 1u);
  // Covering the scene: the blue box too, from a seed on it, and nothing
  // else (the table is not standing, the red box is held).
  options.cover_scene = true;
  const SegmentRun covered = RunOn(scene, options);
  ASSERT_TRUE(covered.summary.ok()) << covered.summary.status();
  ASSERT_EQ(covered.objects.size(), 2u);
  const SegmentedObject& blue = covered.objects[1];
  EXPECT_EQ(scene.frame.labels.at<int>(blue.seed.v, blue.seed.u), 30);
  EXPECT_EQ(cv::countNonZero(blue.mask & covered.objects[0].mask), 0);
  EXPECT_GT(covered.summary->scene_coverage,
            given.summary->scene_coverage + 0.2);
  int cover_stages = 0;
  for (const StageTiming& t : covered.summary->timings) {
    cover_stages += t.stage == "segment.cover";
  }
  EXPECT_GE(cover_stages, 1);
  // max_objects still bounds it.
  options.max_objects = 1;
  EXPECT_EQ(RunOn(scene, options).objects.size(), 1u);
}

TEST(CoverSeedTest, SeedsTheLargestPieceAtItsInnermostPixel) {
  OrganizedCloud cloud;
  cloud.intrinsics = {525.0, 525.0, 20.0, 15.0};
  cloud.xyz = cv::Mat(30, 40, CV_32FC3, cv::Scalar(0.0f, 0.0f, 1.0f));
  cv::Mat free(30, 40, CV_8UC1, cv::Scalar(0));
  free(cv::Rect(2, 2, 5, 5)).setTo(255);      // 25 px
  free(cv::Rect(20, 10, 11, 11)).setTo(255);  // 121 px, centre (25, 15)
  cv::Mat piece;
  const std::optional<cv::Point> at = CoverSeed(cloud, free, 0.0, piece);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(*at, cv::Point(25, 15));
  EXPECT_EQ(cv::countNonZero(piece), 121);
  // 121 px at 1 m and 525 px focal: 4.4e-4 m^2.
  EXPECT_TRUE(CoverSeed(cloud, free, 4e-4, piece).has_value());
  EXPECT_FALSE(CoverSeed(cloud, free, 5e-4, piece).has_value());
  EXPECT_FALSE(CoverSeed(cloud, cv::Mat::zeros(30, 40, CV_8UC1), 0.0, piece)
                   .has_value());
}

TEST(RunSegmentTest, SeedsFromDetectFindBothBoxes) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  const SegmentRun run = RunOn(scene, SegmentOptions{});
  ASSERT_TRUE(run.summary.ok()) << run.summary.status();
  ASSERT_FALSE(run.points.empty());
  std::set<int> found;
  for (const SegmentedObject& o : run.objects) {
    found.insert(scene.frame.labels.at<int>(o.seed.v, o.seed.u));
  }
  EXPECT_TRUE(found.count(20) && found.count(30));
  bool has_detect_stage = false;
  for (const StageTiming& t : run.summary->timings) {
    has_detect_stage |= t.stage == "saliency.sym3d";
  }
  EXPECT_TRUE(has_detect_stage);
}

TEST(RunSegmentTest, AnInterruptOrAFailingSinkStopsTheWork) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  SegmentOptions options;
  options.seeds = {testing::CentreOfLabel(scene.frame.labels, 20),
                   testing::CentreOfLabel(scene.frame.labels, 30)};
  int calls = 0;
  const SegmentRun interrupted = RunOn(scene, options, [&] {
    return ++calls > 3 ? absl::DeadlineExceededError("late") : absl::OkStatus();
  });
  EXPECT_EQ(interrupted.summary.status().code(),
            absl::StatusCode::kDeadlineExceeded);

  static const LinearSvm svm = ArguedSvm();
  SegmentModels models;
  models.cos = &svm;
  SegmentSinks sinks;
  int objects = 0;
  sinks.object = [&](SegmentedObject) {
    ++objects;
    return absl::CancelledError("client gone");
  };
  const absl::StatusOr<SegmentSummary> gone =
      RunSegment(scene.frame.frame, options, models, sinks);
  EXPECT_EQ(gone.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(objects, 1);  // nothing computed after the sink failed
}

TEST(RunSegmentTest, BadRequestsAreNamedErrors) {
  const synth::SynthScene scene = testing::TwoBoxesOnTable();
  SegmentOptions options;
  options.seeds = {{640, 10}};
  EXPECT_EQ(RunOn(scene, options).summary.status().code(),
            absl::StatusCode::kInvalidArgument);
  options = {};
  options.max_objects = -1;
  const absl::Status negative = RunOn(scene, options).summary.status();
  EXPECT_NE(negative.message().find("max_objects"), std::string::npos);
  options = {};
  const absl::StatusOr<SegmentSummary> no_model =
      RunSegment(scene.frame.frame, options, SegmentModels{}, {});
  EXPECT_EQ(no_model.status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(RunSegmentTest, EbsCutsEachOfTwoSeparateBoxesAlongItsEdges) {
  // Edge statistics from random synthetic scenes (not the test scene).
  std::vector<synth::SynthScene> training;
  for (uint64_t seed = 11; seed < 15; ++seed) {
    training.push_back(synth::GenerateScene(seed));
  }
  std::vector<const LabelledFrame*> frames;
  for (const synth::SynthScene& t : training) frames.push_back(&t.frame);
  absl::StatusOr<EbsModel> model = EbsModel::Train(frames, EbsTrainOptions{});
  ASSERT_TRUE(model.ok()) << model.status();
  SegmentModels models;
  models.ebs = &*model;

  // 5 cm apart: each box is ringed by depth and crease edges. (Touching
  // boxes are EBS's weak case: the contour may go round both.)
  const synth::SynthScene scene = testing::TwoBoxesOnTable(0.05f);
  SegmentOptions options;
  options.method = SegmentMethod::kEbs;
  options.seeds = {testing::CentreOfLabel(scene.frame.labels, 20),
                   testing::CentreOfLabel(scene.frame.labels, 30),
                   testing::CentreOfLabel(scene.frame.labels, 20)};
  std::vector<SegmentedObject> objects;
  SegmentSinks sinks;
  sinks.object = [&](SegmentedObject object) {
    objects.push_back(std::move(object));
    return absl::OkStatus();
  };
  const absl::StatusOr<SegmentSummary> summary =
      RunSegment(scene.frame.frame, options, models, sinks);
  ASSERT_TRUE(summary.ok()) << summary.status();
  // The third seed finds the red box again: no second mask of it.
  ASSERT_EQ(objects.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const int label = i == 0 ? 20 : 30;
    const cv::Mat truth = scene.frame.labels == label;
    const double both = cv::countNonZero(objects[i].mask & truth);
    EXPECT_GT(both / cv::countNonZero(objects[i].mask), 0.8) << label;
    EXPECT_GT(both / cv::countNonZero(truth), 0.8) << label;
    EXPECT_GT(objects[i].score, 0.0);
    EXPECT_LE(objects[i].score, 1.0);
  }
  // Without the model EBS cannot run.
  EXPECT_EQ(RunSegment(scene.frame.frame, options, SegmentModels{}, sinks)
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST(ParseSegmentMethodTest, KnowsCosAndEbs) {
  EXPECT_EQ(*ParseSegmentMethod("cos"), SegmentMethod::kCos);
  EXPECT_EQ(*ParseSegmentMethod("ebs"), SegmentMethod::kEbs);
  EXPECT_NE(ParseSegmentMethod("inc").status().message().find("cos, ebs"),
            std::string::npos);
  EXPECT_EQ(SegmentMethodName(SegmentMethod::kEbs), "ebs");
}

}  // namespace
}  // namespace fovea
