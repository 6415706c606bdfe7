#include "server/env_flags.h"

#include <cctype>

#include "absl/flags/commandlineflag.h"
#include "absl/flags/reflection.h"
#include "absl/strings/str_cat.h"

namespace fovea::server {

std::string EnvVariableForFlag(const std::string& flag) {
  std::string name = "FOVEA_";
  for (const char c : flag) {
    name += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return name;
}

absl::Status ApplyFlagsFromEnv(const std::vector<std::string>& flags,
                               const GetEnv& get_env) {
  for (const std::string& flag : flags) {
    const std::string variable = EnvVariableForFlag(flag);
    const char* value = get_env(variable.c_str());
    if (value == nullptr) continue;
    absl::CommandLineFlag* registered = absl::FindCommandLineFlag(flag);
    if (registered == nullptr) {
      return absl::InternalError(
          absl::StrCat(variable, ": no flag --", flag, " to set"));
    }
    std::string error;
    if (!registered->ParseFrom(value, &error)) {
      return absl::InvalidArgumentError(absl::StrCat(
          variable, "=\"", value, "\": not a valid --", flag, ": ", error));
    }
  }
  return absl::OkStatus();
}

}  // namespace fovea::server
