#ifndef FOVEA_CLIENT_OPTION_NAMES_H_
#define FOVEA_CLIENT_OPTION_NAMES_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "fovea/v1/detect.pb.h"
#include "fovea/v1/segment.pb.h"

namespace fovea::client {

// Short, case-insensitive names for the enums of detect.proto and
// segment.proto, as typed on a command line: each value's name without its
// prefix, in lower case, read from the contract's descriptors. Every parser
// returns INVALID_ARGUMENT naming the unknown word and listing the known ones.
// Nothing is checked against what a server implements: a server answers
// UNIMPLEMENTED for what it has not built.

// Saliency channels: names joined by '+', each optionally followed by
// ":WEIGHT" (a number >= 0), e.g. "rso", "ph+sh+rso" (equal weights, 1 each),
// "ph:2+rso:1". Names: those of SaliencyOperator (NameList). An empty string
// gives an empty list (the server's default channels). A name given twice is an
// error.
absl::StatusOr<std::vector<fovea::v1::WeightedOperator>> ParseSaliency(
    absl::string_view text);

// "msr", "wta", "tj".
absl::StatusOr<fovea::v1::Extraction> ParseExtraction(absl::string_view text);
// "none", "simple", "itti".
absl::StatusOr<fovea::v1::Pyramid> ParsePyramid(absl::string_view text);
// "lin", "nms", "nlm".
absl::StatusOr<fovea::v1::Normalization> ParseNormalization(
    absl::string_view text);
// Level combination: "sum", "max".
absl::StatusOr<fovea::v1::LevelCombination> ParseLevelCombination(
    absl::string_view text);
// "sum", "max".
absl::StatusOr<fovea::v1::Fusion> ParseFusion(absl::string_view text);
// "cos", "ebs".
absl::StatusOr<fovea::v1::SegmentationMethod> ParseSegmentationMethod(
    absl::string_view text);
// "generic", "kinect_v1", "active_stereo", "time_of_flight".
absl::StatusOr<fovea::v1::SensorModel> ParseSensorModel(absl::string_view text);

// The names the parsers above accept for `type`'s values, in the
// contract's order, joined by `separator` ("msr | wta | tj"): the flags'
// help text is made of these, so it lists what the contract has.
std::string NameList(const google::protobuf::EnumDescriptor& type,
                     absl::string_view separator = " | ");

// The colour the target_color operator looks for: "R,G,B", three integers
// 0-255 ("200,30,30"); INVALID_ARGUMENT naming `flag` otherwise.
absl::StatusOr<std::array<uint32_t, 3>> ParseRgb(absl::string_view flag,
                                                 absl::string_view text);
// A pixel "U,V" (column, row; integers >= 0), e.g. the location prior's
// centre; INVALID_ARGUMENT naming `flag` otherwise.
absl::StatusOr<fovea::v1::AttentionPixel> ParsePixel(absl::string_view flag,
                                                     absl::string_view text);

// The short name of an operator ("rso" for RSO), the inverse of the names
// ParseSaliency accepts; the proto enum name in lower case for others.
std::string SaliencyName(fovea::v1::SaliencyOperator op);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_OPTION_NAMES_H_
