#include "core/segmentation/cos.h"

#include <gtest/gtest.h>

#include "core/pipeline/detect.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

// A hand-set SVM whose answer can be argued: a convex union (compactness
// 0 mm, feature log10(0 + 0.1) = -1) gives +3 plus the colour correlation;
// a concavity of a centimetre (feature 1) gives -3 plus it; so faces of
// one box join and the other box, whose top lies 4 cm below, does not.
LinearSvm ArguedSvm() {
  return LinearSvm("cos", CosFeatureNames(), {1.0, -3.0}, 0.0, "test");
}

struct Fixture {
  synth::SynthScene synth = testing::TwoBoxesOnTable();
  PreparedScene scene;
  CosScene cos;
};

Fixture MakeFixture() {
  Fixture f;
  absl::StatusOr<PreparedScene> scene =
      PrepareScene(f.synth.frame.frame, DetectOptions{});
  EXPECT_TRUE(scene.ok()) << scene.status();
  f.scene = *std::move(scene);
  absl::StatusOr<CosScene> cos =
      BuildCosScene(f.scene.cloud, f.scene.plane, CosOptions{});
  EXPECT_TRUE(cos.ok()) << cos.status();
  f.cos = *std::move(cos);
  return f;
}

// Precision and recall of `mask` against the pixels labelled `label`.
std::pair<double, double> PrecisionRecall(const cv::Mat& mask,
                                          const cv::Mat& labels, int label) {
  const cv::Mat truth = labels == label;
  const double both = cv::countNonZero(mask & truth);
  return {both / std::max(1, cv::countNonZero(mask)),
          both / std::max(1, cv::countNonZero(truth))};
}

TEST(CosTest, TheTableIsSupportAndEachBoxFaceAPatch) {
  const Fixture f = MakeFixture();
  int support_pixels = 0;
  for (size_t p = 0; p < f.cos.patches.patches.size(); ++p) {
    if (f.cos.support[p]) support_pixels += f.cos.patches.patches[p].points;
  }
  const int table_pixels = cv::countNonZero(f.synth.frame.labels == 1);
  // All but the far rows, seen at a grazing angle, where the support
  // plane's normal test drops points.
  EXPECT_GT(support_pixels, 0.9 * table_pixels);
  EXPECT_LT(support_pixels, 1.01 * table_pixels);
}

TEST(CosTest, ASeedOnEachBoxCutsOutThatBoxAndNotTheOther) {
  Fixture f = MakeFixture();
  const LinearSvm svm = ArguedSvm();
  CosSegmenter segmenter(f.cos, svm, CosOptions{});
  const cv::Mat& labels = f.synth.frame.labels;
  for (const int label : {20, 30}) {
    absl::StatusOr<std::optional<CosObject>> object =
        segmenter.Segment(testing::CentreOfLabel(labels, label));
    ASSERT_TRUE(object.ok()) << object.status();
    ASSERT_TRUE(object->has_value()) << label;
    const auto [precision, recall] =
        PrecisionRecall((*object)->mask, labels, label);
    EXPECT_GT(precision, 0.98) << label;
    // Front and top faces, with their rims (pixels without normals, joined
    // by CosOptions::rim_passes); the sliver of the red side beside the
    // set-back blue box is another patch.
    EXPECT_GT(recall, 0.9) << label;
    EXPECT_GE((*object)->patches.size(), 2u) << label;
    EXPECT_GT((*object)->score, 0.5);
  }
}

TEST(CosTest, ObjectsAreDisjointAndASeedOnATakenPatchYieldsNothing) {
  Fixture f = MakeFixture();
  const LinearSvm svm = ArguedSvm();
  CosSegmenter segmenter(f.cos, svm, CosOptions{});
  const cv::Point red = testing::CentreOfLabel(f.synth.frame.labels, 20);
  ASSERT_TRUE(segmenter.Segment(red).ok());
  absl::StatusOr<std::optional<CosObject>> again = segmenter.Segment(red);
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(again->has_value());
  // On the table (bottom centre of the image) there is nothing to cut out.
  absl::StatusOr<std::optional<CosObject>> table =
      segmenter.Segment({320, 470});
  ASSERT_TRUE(table.ok());
  EXPECT_FALSE(table->has_value());
}

TEST(CosTest, AnAlwaysJoiningSvmSwallowsTheNeighbourButNeverTheTable) {
  // The counter-check of the test above: the separation comes from the
  // SVM, and the table never joins.
  Fixture f = MakeFixture();
  const LinearSvm always("cos", CosFeatureNames(), {0.0, 0.0}, 1.0, "");
  CosSegmenter segmenter(f.cos, always, CosOptions{});
  const cv::Mat& labels = f.synth.frame.labels;
  absl::StatusOr<std::optional<CosObject>> object =
      segmenter.Segment(testing::CentreOfLabel(labels, 20));
  ASSERT_TRUE(object.ok() && object->has_value());
  EXPECT_GT(PrecisionRecall((*object)->mask, labels, 30).second, 0.9);
  // The support patch (160 000 pixels) never joins: only small table
  // remnants along the boxes' bottom edges, which are not support.
  EXPECT_LT(cv::countNonZero((*object)->mask & (labels == 1)),
            0.05 * cv::countNonZero((*object)->mask));
}

TEST(CosTest, InterruptStopsGrowingAndSeedsOutsideAreRejected) {
  Fixture f = MakeFixture();
  const LinearSvm svm = ArguedSvm();
  CosSegmenter segmenter(f.cos, svm, CosOptions{});
  const cv::Point red = testing::CentreOfLabel(f.synth.frame.labels, 20);
  absl::StatusOr<std::optional<CosObject>> stopped = segmenter.Segment(
      red, [] { return absl::CancelledError("client gone"); });
  EXPECT_EQ(stopped.status().code(), absl::StatusCode::kCancelled);
  absl::StatusOr<std::optional<CosObject>> outside =
      segmenter.Segment({-1, 10});
  EXPECT_EQ(outside.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(CosTest, TrainingSamplesSeparateTheBoxesByCompactness) {
  const Fixture f = MakeFixture();
  const std::vector<SvmSample> samples =
      CosTrainingSamples(f.cos, f.synth.frame.labels, 7, CosOptions{});
  double join = 0.0, reject = 0.0;
  int joins = 0, rejects = 0;
  for (const SvmSample& s : samples) {
    EXPECT_EQ(s.group, 7);
    ASSERT_EQ(s.x.size(), CosFeatureNames().size());
    (s.label == 1 ? join : reject) += s.x[1];
    (s.label == 1 ? joins : rejects) += 1;
  }
  ASSERT_GT(joins, 0);
  ASSERT_GT(rejects, 0);
  // Joining a box's own face keeps it convex; joining the other box does
  // not.
  EXPECT_LT(join / joins, reject / rejects);
}

TEST(CosTest, RimsWithoutNormalsJoinTheirPatchOnlyWithRimPasses) {
  // Along the boxes' silhouettes normals are missing (the gradient window
  // crosses the depth jump); rim_passes gives those pixels to the face.
  const synth::SynthScene synth = testing::TwoBoxesOnTable();
  absl::StatusOr<PreparedScene> scene =
      PrepareScene(synth.frame.frame, DetectOptions{});
  ASSERT_TRUE(scene.ok());
  int unlabelled[2] = {0, 0};
  for (const int passes : {0, 1}) {
    CosOptions options;
    options.rim_passes = passes == 0 ? 0 : CosOptions{}.rim_passes;
    absl::StatusOr<CosScene> cos =
        BuildCosScene(scene->cloud, scene->plane, options);
    ASSERT_TRUE(cos.ok());
    for (int v = 0; v < synth.frame.labels.rows; ++v) {
      for (int u = 0; u < synth.frame.labels.cols; ++u) {
        const int label = synth.frame.labels.at<int>(v, u);
        if ((label == 20 || label == 30) &&
            cos->patches.labels.at<int>(v, u) < 0) {
          ++unlabelled[passes];
        }
      }
    }
  }
  EXPECT_GT(unlabelled[0], 100);
  EXPECT_LT(unlabelled[1], unlabelled[0] / 4);
}

TEST(CosOptionsTest, ValidateNamesTheField) {
  CosOptions options;
  options.seed_radius_px = -1;
  EXPECT_NE(Validate(options).message().find("seed_radius_px"),
            std::string::npos);
  options = {};
  options.color.hue_bins = 0;
  EXPECT_NE(Validate(options).message().find("color.hue_bins"),
            std::string::npos);
  options = {};
  options.max_hull_points = 2;
  EXPECT_NE(Validate(options).message().find("max_hull_points"),
            std::string::npos);
  EXPECT_TRUE(Validate(CosOptions{}).ok());
}

}  // namespace
}  // namespace fovea
