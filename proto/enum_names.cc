#include "proto/enum_names.h"

#include <cctype>

namespace fovea::v1 {

std::string EnumValuePrefix(const google::protobuf::EnumDescriptor& type) {
  const std::string& name = type.name();
  std::string prefix;
  for (size_t i = 0; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (i > 0 && std::isupper(c) &&
        !std::isupper(static_cast<unsigned char>(name[i - 1]))) {
      prefix += '_';
    }
    prefix += static_cast<char>(std::toupper(c));
  }
  return prefix + "_";
}

std::string ShortEnumName(const google::protobuf::EnumValueDescriptor& value) {
  const std::string prefix = EnumValuePrefix(*value.type());
  std::string name = value.name();
  if (name.compare(0, prefix.size(), prefix) == 0) name.erase(0, prefix.size());
  for (char& c : name) c = static_cast<char>(std::tolower(c));
  return name;
}

const google::protobuf::EnumValueDescriptor* FindEnumValueByShortName(
    const google::protobuf::EnumDescriptor& type, std::string_view name) {
  std::string upper(name);
  for (char& c : upper) c = static_cast<char>(std::toupper(c));
  if (const auto* full = type.FindValueByName(upper)) return full;
  return type.FindValueByName(EnumValuePrefix(type) + upper);
}

}  // namespace fovea::v1
