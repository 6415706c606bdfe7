#include "tools/eval/realism_eval.h"

#include <gtest/gtest.h>

#include "core/segmentation/relations.h"
#include "core/synth/synth_scene.h"

namespace fovea::eval {
namespace {

TEST(RealismOfFramesTest, LabelledFramesGiveEveryStatistic) {
  const std::vector<LabelledFrame> frames = {synth::GeneratePile(1).frame,
                                             synth::GeneratePile(2).frame};
  absl::StatusOr<RealismSet> set = RealismOfFrames("piles", frames, false);
  ASSERT_TRUE(set.ok()) << set.status();
  EXPECT_EQ(set->frames, 2);
  ASSERT_EQ(set->statistics.size(), RealismStatisticNames().size());
  for (size_t k = 0; k < set->statistics.size(); ++k) {
    EXPECT_FALSE(set->statistics[k].empty()) << RealismStatisticNames()[k];
  }
  // Piles of 8-16 objects: objects, their surfaces and both kinds of pair.
  EXPECT_GE(set->patches_per_object.size(), 8u);
  ASSERT_FALSE(set->same_relations.empty());
  EXPECT_FALSE(set->different_relations.empty());
  EXPECT_EQ(set->same_relations[0].size(), RelationFeatureNames().size());
  // Compared with itself, every statistic agrees.
  for (const RealismDistance& d :
       CompareRealism(*set, *set, RelationFeatureNames())) {
    EXPECT_DOUBLE_EQ(d.ks, 0.0) << d.statistic;
  }
}

TEST(RealismOfFramesTest, UnlabelledFramesGiveTheLabelFreeOnes) {
  LabelledFrame frame = synth::GeneratePile(3).frame;
  frame.labels = cv::Mat();
  absl::StatusOr<RealismSet> set = RealismOfFrames("raw", {frame}, false);
  ASSERT_TRUE(set.ok()) << set.status();
  EXPECT_FALSE(set->statistics[0].empty());  // plane_noise
  EXPECT_TRUE(set->patches_per_object.empty());
  EXPECT_TRUE(set->same_relations.empty());
}

TEST(RunRealismTest, NoSyntheticScenesIsInvalidNoRealSetsComparesNothing) {
  RealismEvalOptions options;
  options.synthetic = 0;
  EXPECT_EQ(RunRealism(options).status().code(),
            absl::StatusCode::kInvalidArgument);
  options.synthetic = 1;
  absl::StatusOr<std::vector<RealismComparison>> none = RunRealism(options);
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
}

}  // namespace
}  // namespace fovea::eval
