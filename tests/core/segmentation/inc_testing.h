#ifndef FOVEA_TESTS_CORE_SEGMENTATION_INC_TESTING_H_
#define FOVEA_TESTS_CORE_SEGMENTATION_INC_TESTING_H_

// Scenes, SVMs and counts shared by INC's tests (inc_test.cc,
// inc_pieces_test.cc).

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/segmentation/inc.h"
#include "core/segmentation/svm_training.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea::testing {

// The relation samples of random synthetic scenes and piles (not the test
// scenes), labelled by their objects.
inline std::vector<SvmSample> SyntheticRelationSamples() {
  std::vector<SvmSample> samples;
  for (uint64_t seed = 21; seed < 33; ++seed) {
    // The piles as rendered when these tests were written (independent
    // Kinect noise), so that the SVM the tests reason about stays the same
    // whatever the generator's sensor models become.
    const synth::SynthScene scene =
        seed % 2 == 0 ? synth::GenerateScene(seed)
                      : synth::RenderScene(
                            synth::RandomSceneSpec(seed, synth::PileOptions()),
                            synth::IndependentKinectV1Noise(), seed);
    absl::StatusOr<std::vector<SvmSample>> s = CollectIncSamples(
        scene.frame, static_cast<int>(seed), DetectOptions{}, IncOptions{});
    if (s.ok()) samples.insert(samples.end(), s->begin(), s->end());
  }
  return samples;
}

// A relation SVM trained on SyntheticRelationSamples.
inline const RbfSvm& TrainedSvm() {
  static const RbfSvm* svm = [] {
    absl::StatusOr<RbfSvm> trained =
        TrainRbfSvm(SyntheticRelationSamples(), RelationFeatureNames(), "inc",
                    RbfSvmTrainingOptions{});
    return new RbfSvm(*std::move(trained));
  }();
  return *svm;
}

// An SVM that has learnt the opposite: trained on the same samples with
// every label flipped, it calls the faces of one box different objects.
inline const RbfSvm& ContrarySvm() {
  static const RbfSvm* svm = [] {
    std::vector<SvmSample> samples = SyntheticRelationSamples();
    for (SvmSample& sample : samples) sample.label = -sample.label;
    absl::StatusOr<RbfSvm> trained = TrainRbfSvm(
        samples, RelationFeatureNames(), "inc", RbfSvmTrainingOptions{});
    return new RbfSvm(*std::move(trained));
  }();
  return *svm;
}

// An upright primitive of `shape` with half sizes `half` (a cylinder's or
// sphere's radius half.x()) centred at `centre`, albedo `rgb`.
inline synth::Primitive Solid(synth::Shape shape, const Eigen::Vector3f& half,
                              const Eigen::Vector3f& centre,
                              const Eigen::Vector3f& rgb) {
  synth::Primitive p;
  p.shape = shape;
  p.half_extents = half;
  p.radius = half.x();
  p.pose.translation() = centre;
  p.rgb = rgb;
  return p;
}

struct Scene {
  synth::SynthScene synth;
  PreparedScene prepared;
};

inline Scene Prepare(synth::SynthScene synth) {
  Scene s{std::move(synth), {}};
  absl::StatusOr<PreparedScene> prepared =
      PrepareScene(s.synth.frame.frame, DetectOptions{});
  EXPECT_TRUE(prepared.ok()) << prepared.status();
  s.prepared = *std::move(prepared);
  return s;
}

inline double Iou(const cv::Mat& mask, const cv::Mat& truth) {
  const double both = cv::countNonZero(mask & truth);
  return both / std::max(1, cv::countNonZero(mask | truth));
}

// A bowl alone on the table, seen from 1 m: radius 9 cm, 3.5 cm deep,
// walls `thickness` thick, Kinect noise.
inline synth::SynthScene BowlOnTable(float thickness) {
  synth::SceneSpec spec;
  spec.camera_pose =
      synth::LookAt(Eigen::Vector3f(0.0f, -0.7f, 0.7f), {0.0f, 0.0f, 0.0f});
  synth::Primitive bowl;
  bowl.shape = synth::Shape::kBowl;
  bowl.radius = 0.09f;
  bowl.thickness = thickness;
  bowl.half_extents = {0.09f, 0.09f, 0.035f};
  bowl.pose.translation() = Eigen::Vector3f(0.0f, 0.0f, 0.035f);
  bowl.rgb = Eigen::Vector3f(0.2f, 0.6f, 0.3f);
  spec.objects.push_back(bowl);
  return synth::RenderScene(spec, synth::NoiseOptions{}, 3);
}

// INC's objects on `scene` with `options` and ContrarySvm: how many lie
// mostly on the object of label 20, and the best IoU of one with it.
inline std::pair<int, double> MasksOnObject(const Scene& scene,
                                            const IncOptions& options) {
  const cv::Mat truth = scene.synth.frame.labels == 20;
  const cv::Mat saliency = AttentionPointsSaliency(
      {CentreOfLabel(scene.synth.frame.labels, 20)}, truth.size(), 20.0f);
  absl::StatusOr<IncScene> inc = BuildIncScene(
      scene.prepared.cloud, scene.prepared.plane, saliency, options);
  EXPECT_TRUE(inc.ok()) << inc.status();
  if (!inc.ok()) return {0, 0.0};
  IncSegmenter segmenter(*inc, ContrarySvm(), options);
  int masks = 0;
  double best = 0.0;
  while (true) {
    absl::StatusOr<std::optional<IncObject>> next = segmenter.Next();
    EXPECT_TRUE(next.ok()) << next.status();
    if (!next.ok() || !next->has_value()) break;
    const cv::Mat& mask = (*next)->mask;
    if (2 * cv::countNonZero(mask & truth) > cv::countNonZero(mask)) ++masks;
    best = std::max(best, Iou(mask, truth));
  }
  return {masks, best};
}

// Per object label of `labels`: how many of INC's masks on `scene` (no
// saliency; relations by `svm`) lie mostly on it, and its best IoU with
// one.
inline std::map<int, std::pair<int, double>> MasksPerObject(
    const Scene& scene, const IncOptions& options,
    const std::vector<int>& labels, const RbfSvm& svm = TrainedSvm()) {
  const cv::Mat& truth_labels = scene.synth.frame.labels;
  const cv::Mat flat(truth_labels.size(), CV_32FC1, cv::Scalar(0));
  std::map<int, std::pair<int, double>> on;
  absl::StatusOr<IncScene> inc =
      BuildIncScene(scene.prepared.cloud, scene.prepared.plane, flat, options,
                    scene.prepared.table.region);
  EXPECT_TRUE(inc.ok()) << inc.status();
  if (!inc.ok()) return on;
  IncSegmenter segmenter(*inc, svm, options);
  while (true) {
    absl::StatusOr<std::optional<IncObject>> next = segmenter.Next();
    EXPECT_TRUE(next.ok()) << next.status();
    if (!next.ok() || !next->has_value()) break;
    const cv::Mat& mask = (*next)->mask;
    for (const int label : labels) {
      const cv::Mat truth = truth_labels == label;
      std::pair<int, double>& o = on[label];
      if (2 * cv::countNonZero(mask & truth) > cv::countNonZero(mask)) {
        ++o.first;
      }
      o.second = std::max(o.second, Iou(mask, truth));
    }
  }
  return on;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_SEGMENTATION_INC_TESTING_H_
