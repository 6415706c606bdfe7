#include "core/segmentation/linear_svm.h"

#include <gtest/gtest.h>

#include <random>

#include "core/segmentation/svm_training.h"

namespace fovea {
namespace {

// Points in [-1, 1]^2, +1 above the line x1 = 0.5 x0 + 0.1, the margin
// band |x1 - 0.5 x0 - 0.1| < 0.05 left out; group = index mod 10.
std::vector<SvmSample> Separable(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<SvmSample> samples;
  while (static_cast<int>(samples.size()) < n) {
    const double x0 = uniform(rng);
    const double x1 = uniform(rng);
    const double side = x1 - 0.5 * x0 - 0.1;
    if (std::abs(side) < 0.05) continue;
    samples.push_back(
        {{x0, x1}, side > 0 ? 1 : -1, static_cast<int>(samples.size() % 10)});
  }
  return samples;
}

TEST(LinearSvmTest, LearnsASeparatingLineThatClassifiesNewPoints) {
  LinearSvmTrainingOptions options;
  options.c = 100.0;
  absl::StatusOr<LinearSvm> svm =
      TrainLinearSvm(Separable(400, 1), {"a", "b"}, "test", options);
  ASSERT_TRUE(svm.ok()) << svm.status();
  int right = 0;
  const std::vector<SvmSample> test = Separable(200, 2);
  for (const SvmSample& s : test) {
    right += (svm->Decision(s.x) > 0) == (s.label == 1) ? 1 : 0;
  }
  EXPECT_GE(right, 196);
  // The direction: w is parallel to (-0.5, 1).
  EXPECT_LT(svm->weights()[0], 0.0);
  EXPECT_NEAR(svm->weights()[0] / svm->weights()[1], -0.5, 0.1);
}

TEST(LinearSvmTest, CrossValidationByGroupIsHighOnSeparableAndChanceOnNoise) {
  LinearSvmTrainingOptions options;
  options.c = 100.0;
  absl::StatusOr<CrossValidation> cv =
      CrossValidateLinearSvm(Separable(300, 3), 5, options);
  ASSERT_TRUE(cv.ok()) << cv.status();
  EXPECT_GT(cv->accuracy, 0.95);
  EXPECT_EQ(cv->folds, 5);
  EXPECT_EQ(cv->samples, 300);
  // Labels independent of the features: nothing to learn.
  std::vector<SvmSample> noise = Separable(300, 4);
  std::mt19937_64 rng(5);
  for (SvmSample& s : noise) s.label = (rng() & 1) ? 1 : -1;
  cv = CrossValidateLinearSvm(noise, 5, options);
  ASSERT_TRUE(cv.ok()) << cv.status();
  EXPECT_LT(cv->balanced_accuracy, 0.62);
}

TEST(LinearSvmTest, SerializeAndParseGiveTheSameModel) {
  const LinearSvm svm("cos", {"color", "compact"}, {1.25, -3.5e-7}, 0.1,
                      "made by a test");
  absl::StatusOr<LinearSvm> back = LinearSvm::Parse(svm.Serialize(), "cos");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->weights(), svm.weights());
  EXPECT_EQ(back->bias(), svm.bias());
  EXPECT_EQ(back->feature_names(), svm.feature_names());
  EXPECT_EQ(back->provenance(), "made by a test");
  EXPECT_EQ(back->Version(), svm.Version());
  EXPECT_EQ(svm.Version().rfind("cos-", 0), 0u);
  const LinearSvm other("cos", {"color", "compact"}, {1.25, -3.5e-7}, 0.2,
                        "made by a test");
  EXPECT_NE(other.Version(), svm.Version());
}

TEST(LinearSvmTest, ParseRejectsWhatIsNotAModelAndSaysWhere) {
  const std::string good =
      LinearSvm("cos", {"a", "b"}, {1, 2}, 3, "").Serialize();
  struct Case {
    std::string text;
    std::string message;
  };
  const Case cases[] = {
      {"", "line 1"},
      {"hello\nkind cos\n", "line 1"},
      {"fovea-linear-svm 2\n", "line 1"},
      {"fovea-linear-svm 1\nkind cos\nfeatures a b\nweights 1 nan\nbias 0\n",
       "not a finite number"},
      {"fovea-linear-svm 1\nkind cos\nfeatures a b\nweights 1\nbias 0\n",
       "1 weights for 2 features"},
      {"fovea-linear-svm 1\nkind cos\nfeatures a\nweights 1\n", "'bias'"},
      {"fovea-linear-svm 1\nkind cos\nkind cos\n", "repeated"},
      {"fovea-linear-svm 1\nkind ebs\nfeatures a\nweights 1\nbias 0\n",
       "expected 'cos'"},
      {"fovea-linear-svm 1\nwat 3\n", "unknown key"},
      {good.substr(0, good.size() / 2), "missing"},
      {std::string(2 << 20, 'x'), "bytes"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<LinearSvm> svm = LinearSvm::Parse(c.text, "cos");
    ASSERT_FALSE(svm.ok()) << c.text.substr(0, 80);
    EXPECT_EQ(svm.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(svm.status().message().find(c.message), std::string::npos)
        << svm.status() << " for " << c.text.substr(0, 80);
  }
}

TEST(LinearSvmTest, TrainingNeedsTwoClassesAndConsistentSamples) {
  const LinearSvmTrainingOptions options;
  EXPECT_FALSE(TrainLinearSvm({}, {}, "t", options).ok());
  EXPECT_FALSE(
      TrainLinearSvm({{{1.0}, 1, 0}, {{2.0}, 1, 0}}, {"a"}, "t", options).ok());
  EXPECT_FALSE(
      TrainLinearSvm({{{1.0}, 1, 0}, {{2.0, 1.0}, -1, 0}}, {"a"}, "t", options)
          .ok());
  EXPECT_FALSE(
      TrainLinearSvm({{{1.0}, 2, 0}, {{2.0}, -1, 0}}, {"a"}, "t", options)
          .ok());
  LinearSvmTrainingOptions bad;
  bad.c = 0.0;
  EXPECT_NE(Validate(bad).message().find("c must"), std::string::npos);
  EXPECT_FALSE(CrossValidateLinearSvm(Separable(10, 1), 1, options).ok());
}

}  // namespace
}  // namespace fovea
