#include "client/option_names.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea::client {
namespace {

using ::testing::HasSubstr;

TEST(ParseSaliencyTest, PlusJoinsEqualWeights) {
  absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ops =
      ParseSaliency("ph+sh+rso");
  ASSERT_TRUE(ops.ok()) << ops.status();
  ASSERT_EQ(ops->size(), 3u);
  EXPECT_EQ((*ops)[0].op(), fovea::v1::SALIENCY_OPERATOR_PH);
  EXPECT_EQ((*ops)[1].op(), fovea::v1::SALIENCY_OPERATOR_SH);
  EXPECT_EQ((*ops)[2].op(), fovea::v1::SALIENCY_OPERATOR_RSO);
  for (const auto& op : *ops) EXPECT_EQ(op.weight(), 1.0);
}

TEST(ParseSaliencyTest, EveryNameMapsToItsEnumAndBack) {
  const std::pair<const char*, fovea::v1::SaliencyOperator> cases[] = {
      {"ph", fovea::v1::SALIENCY_OPERATOR_PH},
      {"sh", fovea::v1::SALIENCY_OPERATOR_SH},
      {"rso", fovea::v1::SALIENCY_OPERATOR_RSO},
      {"sym3d", fovea::v1::SALIENCY_OPERATOR_SYM3D},
      {"itti", fovea::v1::SALIENCY_OPERATOR_ITTI},
      {"harel", fovea::v1::SALIENCY_OPERATOR_HAREL},
      {"hou", fovea::v1::SALIENCY_OPERATOR_HOU},
      {"kootstra", fovea::v1::SALIENCY_OPERATOR_KOOTSTRA},
      {"target_color", fovea::v1::SALIENCY_OPERATOR_TARGET_COLOR},
      {"location_prior", fovea::v1::SALIENCY_OPERATOR_LOCATION_PRIOR}};
  for (const auto& [name, op] : cases) {
    absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ops =
        ParseSaliency(name);
    ASSERT_TRUE(ops.ok()) << name << ": " << ops.status();
    ASSERT_EQ(ops->size(), 1u);
    EXPECT_EQ((*ops)[0].op(), op) << name;
    EXPECT_EQ(SaliencyName(op), name);
  }
}

TEST(ParseSaliencyTest, WeightsAndCaseAreAccepted) {
  absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ops =
      ParseSaliency("PH:2+Rso:0.5");
  ASSERT_TRUE(ops.ok()) << ops.status();
  ASSERT_EQ(ops->size(), 2u);
  EXPECT_EQ((*ops)[0].op(), fovea::v1::SALIENCY_OPERATOR_PH);
  EXPECT_EQ((*ops)[0].weight(), 2.0);
  EXPECT_EQ((*ops)[1].op(), fovea::v1::SALIENCY_OPERATOR_RSO);
  EXPECT_EQ((*ops)[1].weight(), 0.5);
}

TEST(ParseSaliencyTest, EmptyMeansServerDefault) {
  absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ops =
      ParseSaliency("");
  ASSERT_TRUE(ops.ok());
  EXPECT_TRUE(ops->empty());
}

TEST(ParseSaliencyTest, UnknownNameIsNamed) {
  absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ops =
      ParseSaliency("bogus");
  ASSERT_EQ(ops.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(ops.status().message(), HasSubstr("\"bogus\""));
  EXPECT_THAT(ops.status().message(), HasSubstr("rso"));  // lists known ones
  EXPECT_THAT(ParseSaliency("ph+bogus").status().message(), HasSubstr("bogus"));
}

TEST(ParseSaliencyTest, BadWeightEmptyTermAndRepeatsAreRefused) {
  EXPECT_EQ(ParseSaliency("ph:-1").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseSaliency("ph:x").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseSaliency("ph++rso").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(ParseSaliency("rso+rso").status().message(), HasSubstr("twice"));
}

TEST(ParseEnumsTest, ShortNamesMapToProtoEnums) {
  EXPECT_EQ(*ParseExtraction("msr"), fovea::v1::EXTRACTION_MSR);
  EXPECT_EQ(*ParseExtraction("wta"), fovea::v1::EXTRACTION_WTA);
  EXPECT_EQ(*ParseExtraction("TJ"), fovea::v1::EXTRACTION_TJ);
  EXPECT_EQ(*ParsePyramid("none"), fovea::v1::PYRAMID_NONE);
  EXPECT_EQ(*ParsePyramid("simple"), fovea::v1::PYRAMID_SIMPLE);
  EXPECT_EQ(*ParsePyramid("itti"), fovea::v1::PYRAMID_ITTI);
  EXPECT_EQ(*ParseNormalization("lin"), fovea::v1::NORMALIZATION_LIN);
  EXPECT_EQ(*ParseNormalization("nms"), fovea::v1::NORMALIZATION_NMS);
  EXPECT_EQ(*ParseNormalization("nlm"), fovea::v1::NORMALIZATION_NLM);
  EXPECT_EQ(*ParseLevelCombination("sum"), fovea::v1::LEVEL_COMBINATION_SUM);
  EXPECT_EQ(*ParseLevelCombination("max"), fovea::v1::LEVEL_COMBINATION_MAX);
  EXPECT_EQ(*ParseFusion("sum"), fovea::v1::FUSION_SUM);
  EXPECT_EQ(*ParseFusion("max"), fovea::v1::FUSION_MAX);
  EXPECT_EQ(*ParseSegmentationMethod("cos"),
            fovea::v1::SEGMENTATION_METHOD_COS);
  EXPECT_EQ(*ParseSegmentationMethod("ebs"),
            fovea::v1::SEGMENTATION_METHOD_EBS);
}

TEST(ParseEnumsTest, UnknownNamesNameTheFlag) {
  absl::StatusOr<fovea::v1::Extraction> extraction = ParseExtraction("best");
  ASSERT_EQ(extraction.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(extraction.status().message(), HasSubstr("extract"));
  EXPECT_THAT(extraction.status().message(), HasSubstr("best"));
  EXPECT_THAT(ParseFusion("avg").status().message(), HasSubstr("fusion"));
  EXPECT_THAT(ParseSegmentationMethod("grabcut").status().message(),
              HasSubstr("method"));
}

}  // namespace
}  // namespace fovea::client
