#include "core/segmentation/ebs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

// Synthetic table scenes with noise; seeds 1..20 hold 2-6 objects.
std::vector<synth::SynthScene> Scenes(std::vector<uint64_t> seeds) {
  std::vector<synth::SynthScene> scenes;
  for (const uint64_t seed : seeds) {
    scenes.push_back(synth::GenerateScene(seed));
  }
  return scenes;
}

std::vector<const LabelledFrame*> Frames(
    const std::vector<synth::SynthScene>& scenes) {
  std::vector<const LabelledFrame*> frames;
  for (const synth::SynthScene& s : scenes) frames.push_back(&s.frame);
  return frames;
}

// One model for the whole file: training renders and builds four scenes.
class EbsModelTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    training_ = new std::vector<synth::SynthScene>(Scenes({1, 2, 3, 4}));
    absl::StatusOr<EbsModel> model =
        EbsModel::Train(Frames(*training_), EbsTrainOptions{});
    ASSERT_TRUE(model.ok()) << model.status();
    model_ = new EbsModel(*std::move(model));
  }
  static void TearDownTestSuite() {
    delete model_;
    delete training_;
  }

  static OrganizedCloud CloudOf(const LabelledFrame& frame) {
    absl::StatusOr<OrganizedCloud> cloud =
        BuildOrganizedCloud(frame.frame, model_->options().normals);
    EXPECT_TRUE(cloud.ok()) << cloud.status();
    return cloud.ok() ? *std::move(cloud) : OrganizedCloud{};
  }

  static std::vector<synth::SynthScene>* training_;
  static EbsModel* model_;
};

std::vector<synth::SynthScene>* EbsModelTest::training_ = nullptr;
EbsModel* EbsModelTest::model_ = nullptr;

TEST_F(EbsModelTest, EdgeProbabilityIsHigherOnBoundariesThanInsideObjects) {
  for (const synth::SynthScene& scene : Scenes({5, 6})) {
    const OrganizedCloud cloud = CloudOf(scene.frame);
    const cv::Mat p = model_->EdgeProbability(cloud);
    ASSERT_EQ(p.type(), CV_32FC1);
    ASSERT_EQ(p.size(), cloud.xyz.size());
    absl::StatusOr<cv::Mat> boundary =
        BoundaryLabels(scene.frame.labels, cloud.xyz, 1, 0);
    ASSERT_TRUE(boundary.ok()) << boundary.status();
    // Inside objects: object pixels 5 px or more from any boundary.
    cv::Mat inside = scene.frame.labels >= 20;
    cv::erode(inside, inside, cv::Mat::ones(11, 11, CV_8UC1));
    double on_edge = 0.0, in_object = 0.0;
    int n_edge = 0, n_inside = 0;
    for (int v = 0; v < p.rows; ++v) {
      for (int u = 0; u < p.cols; ++u) {
        const float x = p.at<float>(v, u);
        ASSERT_GE(x, 0.0f);
        ASSERT_LE(x, 1.0f);
        if (boundary->at<uint8_t>(v, u) == 255) {
          on_edge += x;
          ++n_edge;
        } else if (inside.at<uint8_t>(v, u) && cloud.HasPoint(u, v)) {
          in_object += x;
          ++n_inside;
        }
      }
    }
    ASSERT_GT(n_edge, 100) << scene.frame.name;
    ASSERT_GT(n_inside, 1000) << scene.frame.name;
    EXPECT_GT(on_edge / n_edge, 0.7) << scene.frame.name;
    EXPECT_LT(in_object / n_inside, 0.3) << scene.frame.name;
  }
}

// On noisy synthetic scenes curvature alone is nearly perfect (the
// rendered folds are sharp); the fused map must be as good as the best
// cue and better than colour and depth.
TEST_F(EbsModelTest, FusedMapClassifiesHeldOutBoundariesAsWellAsTheBestCue) {
  const std::vector<synth::SynthScene> held_out = Scenes({7, 8});
  absl::StatusOr<EbsEvaluation> e = model_->Evaluate(Frames(held_out));
  ASSERT_TRUE(e.ok()) << e.status();
  const double fused = e->fused.BalancedAccuracy();
  EXPECT_GT(fused, 0.9);
  EXPECT_GT(fused, e->color.BalancedAccuracy());
  EXPECT_GT(fused, e->depth.BalancedAccuracy());
  EXPECT_GT(fused, e->curvature.BalancedAccuracy() - 0.01);
  EXPECT_GT(e->fused.Accuracy(), 0.9);
}

TEST_F(EbsModelTest, PixelsWithoutDepthAreEdges) {
  const OrganizedCloud cloud = CloudOf((*training_)[0].frame);
  const EdgeMaps maps = ComputeEdgeMaps(cloud, model_->edge_map_options());
  const cv::Mat p = model_->EdgeProbability(maps);
  int without_depth = 0;
  for (int v = 0; v < p.rows; ++v) {
    for (int u = 0; u < p.cols; ++u) {
      if (!cloud.HasPoint(u, v)) {
        ++without_depth;
        ASSERT_EQ(p.at<float>(v, u), 1.0f);
      }
    }
  }
  EXPECT_GT(without_depth, 0);
}

TEST_F(EbsModelTest, ACueMissingAtAPixelIsLeftOut) {
  const OrganizedCloud cloud = CloudOf((*training_)[0].frame);
  EdgeMaps maps = ComputeEdgeMaps(cloud, model_->edge_map_options());
  EdgeMaps without_colour = maps;
  without_colour.color = maps.color.clone();
  without_colour.color.setTo(std::numeric_limits<float>::quiet_NaN());
  const cv::Mat all = model_->EdgeProbability(maps);
  const cv::Mat some = model_->EdgeProbability(without_colour);
  // Defined and different: the colour cue moved the probabilities.
  EXPECT_EQ(cv::countNonZero(some != some), 0);
  EXPECT_GT(cv::norm(all, some, cv::NORM_L1), 1.0);
}

TEST(EbsTrainerTest, FinishWithoutFramesIsFailedPrecondition) {
  absl::StatusOr<EbsTrainer> trainer = EbsTrainer::Create({});
  ASSERT_TRUE(trainer.ok()) << trainer.status();
  EXPECT_EQ(trainer->Finish().status().code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST(EbsTrainerTest, RejectsInvalidOptionsAndMalformedFrames) {
  EbsTrainOptions bad;
  bad.boundary_band_px = 0;
  EXPECT_NE(EbsTrainer::Create(bad).status().message().find("boundary_band_px"),
            absl::string_view::npos);
  bad = {};
  bad.depth_bins.bins = 1;
  EXPECT_NE(EbsTrainer::Create(bad).status().message().find("depth_bins"),
            absl::string_view::npos);

  absl::StatusOr<EbsTrainer> trainer = EbsTrainer::Create({});
  ASSERT_TRUE(trainer.ok());
  synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.05f, 0.05f, 0.05f));
  scene.frame.labels = cv::Mat(10, 10, CV_32SC1, cv::Scalar(1));
  EXPECT_EQ(trainer->Add(scene.frame).code(),
            absl::StatusCode::kInvalidArgument);
  LabelledFrame empty;
  EXPECT_EQ(trainer->Add(empty).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EbsModel::Train({nullptr}, EbsTrainOptions{}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// A box on the table trains a model on its own; only the table and one
// object, so one boundary.
TEST(EbsTrainerTest, OneBoxOnATableIsEnoughToTrain) {
  const synth::SynthScene scene =
      testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
  absl::StatusOr<EbsModel> model =
      EbsModel::Train({&scene.frame}, EdgeMapOptions{}, NormalOptions{});
  ASSERT_TRUE(model.ok()) << model.status();
  int64_t edges = 0, others = 0;
  for (const EbsModel::Cue& cue : model->cues()) {
    for (const int64_t c : cue.edge) edges += c;
    for (const int64_t c : cue.no_edge) others += c;
  }
  EXPECT_GT(edges, 0);
  EXPECT_GT(others, 10 * edges);
}

// 0 no data, 1 table, 20/21 two parts of object 2, 30 object 3.
TEST(BoundaryLabelsTest, MarksPixelsNearAnotherRegionOnly) {
  cv::Mat labels = (cv::Mat_<int>(3, 8) <<  //
                        1,
                    1, 1, 20, 21, 21, 30, 0,     //
                    1, 1, 1, 20, 21, 21, 30, 0,  //
                    1, 1, 1, 20, 20, 20, 30, 30);
  absl::StatusOr<cv::Mat> b = BoundaryLabels(labels, cv::Mat(), 1, 0);
  ASSERT_TRUE(b.ok()) << b.status();
  const cv::Mat expected = (cv::Mat_<uint8_t>(3, 8) <<  //
                                1,
                            1, 255, 255, 1, 255, 255, 0,     //
                            1, 1, 255, 255, 1, 255, 255, 0,  //
                            1, 1, 255, 255, 1, 255, 255, 1);
  EXPECT_EQ(cv::countNonZero(*b != expected), 0) << *b;
  // With an ignore band of 1 the pixels 2 px from another region drop out.
  b = BoundaryLabels(labels, cv::Mat(), 1, 1);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->at<uint8_t>(0, 1), 0);
  EXPECT_EQ(b->at<uint8_t>(0, 0), 1);
  EXPECT_EQ(b->at<uint8_t>(0, 4), 0);
}

TEST(BoundaryLabelsTest, RejectsWrongTypesAndBands) {
  EXPECT_FALSE(BoundaryLabels(cv::Mat(3, 3, CV_8UC1), cv::Mat(), 1, 0).ok());
  EXPECT_FALSE(BoundaryLabels(cv::Mat(3, 3, CV_32SC1, cv::Scalar(1)),
                              cv::Mat(4, 3, CV_32FC3), 1, 0)
                   .ok());
  EXPECT_FALSE(
      BoundaryLabels(cv::Mat(3, 3, CV_32SC1, cv::Scalar(1)), cv::Mat(), 0, 0)
          .ok());
}

}  // namespace
}  // namespace fovea
