#include "core/segmentation/rbf_svm.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "core/baseline/scene_segmenters.h"
#include "core/segmentation/svm_training.h"

namespace fovea {
namespace {

// Inside the disc of radius 0.5 around (0.5, 0.5): +1; outside, in the unit
// square: -1. Not linearly separable. group = index mod 5.
std::vector<SvmSample> Disc(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<SvmSample> samples;
  while (static_cast<int>(samples.size()) < n) {
    const double x = uniform(rng);
    const double y = uniform(rng);
    const double r = std::hypot(x - 0.5, y - 0.5);
    if (std::abs(r - 0.35) < 0.03) continue;
    samples.push_back(
        {{x, y}, r < 0.35 ? 1 : -1, static_cast<int>(samples.size() % 5)});
  }
  return samples;
}

TEST(RbfSvmTest, SeparatesADiscWithCalibratedProbabilities) {
  absl::StatusOr<RbfSvm> svm =
      TrainRbfSvm(Disc(400, 1), {"x", "y"}, "test", RbfSvmTrainingOptions{});
  ASSERT_TRUE(svm.ok()) << svm.status();
  int right = 0;
  for (const SvmSample& s : Disc(200, 2)) {
    right += (svm->Probability(s.x) > 0.5) == (s.label == 1) ? 1 : 0;
  }
  EXPECT_GE(right, 185);
  // The centre is surely inside, a corner surely outside.
  EXPECT_GT(svm->Probability({0.5, 0.5}), 0.9);
  EXPECT_LT(svm->Probability({0.02, 0.02}), 0.1);
  const absl::StatusOr<CrossValidation> cv =
      CrossValidateRbfSvm(Disc(300, 3), 5, RbfSvmTrainingOptions{});
  ASSERT_TRUE(cv.ok()) << cv.status();
  EXPECT_GT(cv->accuracy, 0.9);
}

// PCL's pcl_ml, which pcl_segmentation loads, exports a libsvm of its own
// (older, another svm_model). This executable lists PCL before
// fovea_training: with the shared libsvm its calls to svm_train bound to
// PCL's, and every probability came out as one minus itself. Training holds
// libsvm's static library whole, and its calls bind there.
TEST(RbfSvmTest, TrainsWithLibsvmEvenWithPclLinkedFirst) {
  EXPECT_TRUE(Validate(EuclideanSceneOptions{}).ok());  // from PCL's user
  Dl_info bound{};
  ASSERT_NE(dladdr(dlsym(RTLD_DEFAULT, "svm_train"), &bound), 0);
  Dl_info self{};
  ASSERT_NE(dladdr(reinterpret_cast<void*>(&Disc), &self), 0);
  EXPECT_STREQ(bound.dli_fname, self.dli_fname);
  absl::StatusOr<RbfSvm> svm =
      TrainRbfSvm(Disc(200, 4), {"x", "y"}, "test", RbfSvmTrainingOptions{});
  ASSERT_TRUE(svm.ok()) << svm.status();
  EXPECT_GT(svm->Probability({0.5, 0.5}), 0.9);
  EXPECT_LT(svm->Probability({0.02, 0.02}), 0.1);
}

TEST(RbfSvmTest, SerializeAndParseGiveTheSameDecisions) {
  absl::StatusOr<RbfSvm> svm =
      TrainRbfSvm(Disc(100, 4), {"x", "y"}, "inc", RbfSvmTrainingOptions{});
  ASSERT_TRUE(svm.ok());
  absl::StatusOr<RbfSvm> back = RbfSvm::Parse(svm->Serialize(), "inc");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Version(), svm->Version());
  for (const SvmSample& s : Disc(20, 5)) {
    EXPECT_DOUBLE_EQ(back->Probability(s.x), svm->Probability(s.x));
  }
}

TEST(RbfSvmTest, TheSameSamplesGiveTheSameModelWhateverTrainedBefore) {
  const std::vector<SvmSample> samples = Disc(120, 7);
  absl::StatusOr<RbfSvm> first =
      TrainRbfSvm(samples, {"x", "y"}, "inc", RbfSvmTrainingOptions{});
  ASSERT_TRUE(first.ok());
  // Other training in between draws from libsvm's random numbers.
  ASSERT_TRUE(
      CrossValidateRbfSvm(Disc(100, 8), 5, RbfSvmTrainingOptions{}).ok());
  std::rand();
  absl::StatusOr<RbfSvm> second =
      TrainRbfSvm(samples, {"x", "y"}, "inc", RbfSvmTrainingOptions{});
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(first->Serialize(), second->Serialize());
}

TEST(RbfSvmTest, ParseRejectsCorruptText) {
  absl::StatusOr<RbfSvm> svm =
      TrainRbfSvm(Disc(60, 6), {"x", "y"}, "inc", RbfSvmTrainingOptions{});
  ASSERT_TRUE(svm.ok());
  const std::string good = svm->Serialize();
  const std::string cases[] = {
      "",
      "fovea-linear-svm 1\n",
      good.substr(0, good.size() / 2),
      good + "1 2 3\n",
      "fovea-rbf-svm 1\nkind inc\nfeatures x y\ngamma -1\nrho 0\n"
      "probability 1 0\nprovenance\nvectors 0\n",
      "fovea-rbf-svm 1\nkind inc\nfeatures x y\ngamma 1\nrho 0\n"
      "probability 1 0\nprovenance\nvectors 99999999\n",
      "fovea-rbf-svm 1\nkind inc\nfeatures x y\ngamma 1\nrho 0\n"
      "probability 1 0\nprovenance\nvectors 1\n1 2\n",
      "fovea-rbf-svm 1\nkind cos\nfeatures x y\ngamma 1\nrho 0\n"
      "probability 1 0\nprovenance\nvectors 0\n",
  };
  for (const std::string& text : cases) {
    const absl::StatusOr<RbfSvm> parsed = RbfSvm::Parse(text, "inc");
    EXPECT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument)
        << text.substr(0, 60);
  }
  RbfSvmTrainingOptions bad;
  bad.gamma = 0.0;
  EXPECT_NE(Validate(bad).message().find("gamma"), std::string::npos);
}

}  // namespace
}  // namespace fovea
