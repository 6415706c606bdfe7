#ifndef FOVEA_PROTO_ENUM_NAMES_H_
#define FOVEA_PROTO_ENUM_NAMES_H_

#include <google/protobuf/descriptor.h>

#include <string>
#include <string_view>

namespace fovea::v1 {

// The wire contract's enum values carry their enum's name as a prefix
// (Buf's ENUM_VALUE_PREFIX: SALIENCY_OPERATOR_SYM3D, PYRAMID_ITTI,
// STOP_REASON_DONE). The rest of Fovea spells a value by what follows the
// prefix, in lower case ("sym3d", "itti", "done"): core's registries,
// the command-line tools, the Python client's keyword arguments.

// The prefix of `type`'s values: its name in upper snake case and "_"
// ("SALIENCY_OPERATOR_" for SaliencyOperator, "FORMAT_" for
// ObjectPointsOptions.Format).
std::string EnumValuePrefix(const google::protobuf::EnumDescriptor& type);

// The value's name without its prefix, in lower case ("sym3d").
std::string ShortEnumName(const google::protobuf::EnumValueDescriptor& value);

// The value of `type` whose short name is `name` (any case; the full name
// is accepted too); null when there is none.
const google::protobuf::EnumValueDescriptor* FindEnumValueByShortName(
    const google::protobuf::EnumDescriptor& type, std::string_view name);

}  // namespace fovea::v1

#endif  // FOVEA_PROTO_ENUM_NAMES_H_
