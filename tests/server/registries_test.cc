// The saliency registry (core/pipeline/saliency_registry.h) is the one
// table of operators: every row is reachable through the wire contract,
// the server's conversion and capabilities, and fovea-client's names, and
// every operator of the wire contract has a row.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "absl/strings/ascii.h"
#include "client/option_names.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/saliency_registry.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/segment.pb.h"
#include "proto/enum_names.h"
#include "server/capabilities.h"
#include "server/convert.h"

namespace fovea::server {
namespace {

TEST(RegistriesTest, EveryRowIsReachableThroughEveryLayer) {
  const v1::GetCapabilitiesResponse capabilities =
      BuildCapabilities(FrameLimits{}, 0, {});
  const std::set<int> listed(capabilities.saliency_operators().begin(),
                             capabilities.saliency_operators().end());
  std::set<std::string> names;
  for (const SaliencyOperator& row : SaliencyOperators()) {
    const std::string name(row.name);
    SCOPED_TRACE(name);
    EXPECT_TRUE(names.insert(name).second) << "a name given twice";
    EXPECT_EQ(name, absl::AsciiStrToLower(name));
    EXPECT_EQ(name.find('-'), std::string::npos) << "one spelling: '_'";
    // Core: names and values round-trip.
    EXPECT_EQ(FindSaliencyOperator(row.op), &row);
    EXPECT_EQ(FindSaliencyOperator(row.name), &row);
    EXPECT_EQ(SaliencyOpName(row.op), row.name);
    absl::StatusOr<std::vector<SaliencyOp>> parsed = ParseSaliencyOps(name);
    ASSERT_TRUE(parsed.ok()) << parsed.status();
    EXPECT_THAT(*parsed, ::testing::ElementsAre(row.op));
    // The wire: a value of that name, converted both ways.
    v1::SaliencyOperator value = v1::SALIENCY_OPERATOR_UNSPECIFIED;
    ASSERT_TRUE(v1::SaliencyOperator_Parse(
        "SALIENCY_OPERATOR_" + absl::AsciiStrToUpper(name), &value))
        << "no SaliencyOperator value SALIENCY_OPERATOR_"
        << absl::AsciiStrToUpper(name);
    EXPECT_EQ(ToProtoEnum(row.op), value);
    v1::DetectOptions wire;
    wire.add_saliency()->set_op(value);
    wire.add_target_color_rgb(200);
    wire.add_target_color_rgb(30);
    wire.add_target_color_rgb(30);
    wire.mutable_location_prior()->set_u(10);
    wire.mutable_location_prior()->set_v(10);
    absl::StatusOr<DetectOptions> options = ToDetectOptions(wire);
    ASSERT_TRUE(options.ok()) << options.status();
    ASSERT_EQ(options->channels.size(), 1u);
    EXPECT_EQ(options->channels[0].op, row.op);
    // Capabilities list it.
    EXPECT_TRUE(listed.count(value)) << "not in GetCapabilities";
    // fovea-client takes the same name.
    absl::StatusOr<std::vector<v1::WeightedOperator>> client =
        client::ParseSaliency(name);
    ASSERT_TRUE(client.ok()) << client.status();
    ASSERT_EQ(client->size(), 1u);
    EXPECT_EQ((*client)[0].op(), value);
    EXPECT_EQ(client::SaliencyName(value), name);
  }
  // Every operator of the wire contract has a row.
  const google::protobuf::EnumDescriptor* values =
      v1::SaliencyOperator_descriptor();
  for (int i = 0; i < values->value_count(); ++i) {
    if (values->value(i)->number() == v1::SALIENCY_OPERATOR_UNSPECIFIED) {
      continue;
    }
    EXPECT_TRUE(names.count(v1::ShortEnumName(*values->value(i))))
        << values->value(i)->name() << " has no registry row";
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(values->value_count() - 1));
}

// The same for the other two tables: extractions and segmentation methods.
TEST(RegistriesTest, ExtractionsAndSegmentMethodsAreReachableToo) {
  const v1::GetCapabilitiesResponse capabilities =
      BuildCapabilities(FrameLimits{}, 0, {});
  const std::set<int> extractions(capabilities.extractions().begin(),
                                  capabilities.extractions().end());
  for (const Extraction& row : Extractions()) {
    const std::string name(row.name);
    SCOPED_TRACE(name);
    v1::Extraction value = v1::EXTRACTION_UNSPECIFIED;
    ASSERT_TRUE(v1::Extraction_Parse(
        "EXTRACTION_" + absl::AsciiStrToUpper(name), &value));
    EXPECT_EQ(ToProtoEnum(row.kind), value);
    v1::DetectOptions wire;
    wire.set_extraction(value);
    absl::StatusOr<DetectOptions> options = ToDetectOptions(wire);
    ASSERT_TRUE(options.ok()) << options.status();
    EXPECT_EQ(options->extraction, row.kind);
    EXPECT_EQ(*ParseExtraction(name), row.kind);
    EXPECT_EQ(*client::ParseExtraction(name), value);
    EXPECT_TRUE(extractions.count(value));
  }
  EXPECT_EQ(
      Extractions().size(),
      static_cast<size_t>(v1::Extraction_descriptor()->value_count() - 1));

  const std::set<int> methods(capabilities.segmentation_methods().begin(),
                              capabilities.segmentation_methods().end());
  for (const SegmentMethodRow& row : SegmentMethods()) {
    const std::string name(row.name);
    SCOPED_TRACE(name);
    v1::SegmentationMethod value = v1::SEGMENTATION_METHOD_UNSPECIFIED;
    ASSERT_TRUE(v1::SegmentationMethod_Parse(
        "SEGMENTATION_METHOD_" + absl::AsciiStrToUpper(name), &value));
    EXPECT_EQ(ToProtoEnum(row.method), value);
    v1::SegmentRequest request;
    request.set_method(value);
    absl::StatusOr<SegmentOptions> options = ToSegmentOptions(request);
    ASSERT_TRUE(options.ok()) << options.status();
    EXPECT_EQ(options->method, row.method);
    EXPECT_EQ(SegmentMethodName(row.method), row.name);
    EXPECT_EQ(*client::ParseSegmentationMethod(name), value);
    EXPECT_TRUE(methods.count(value));
  }
  EXPECT_EQ(SegmentMethods().size(),
            static_cast<size_t>(
                v1::SegmentationMethod_descriptor()->value_count() - 1));
}

TEST(RegistriesTest, UnknownNamesListTheKnownOnes) {
  const absl::Status bad = ParseSaliencyOps("ph+target-color").status();
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), ::testing::HasSubstr("target_color"));
  EXPECT_THAT(bad.message(), ::testing::HasSubstr("'target-color'"));
}

}  // namespace
}  // namespace fovea::server
