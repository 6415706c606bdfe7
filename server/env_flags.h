#ifndef FOVEA_SERVER_ENV_FLAGS_H_
#define FOVEA_SERVER_ENV_FLAGS_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"

// Flags from the environment, for containers: FOVEA_LISTEN=0.0.0.0:50051
// sets --listen. The command line still wins, because main parses it
// afterwards.

namespace fovea::server {

// The variable that sets flag `flag`: "FOVEA_" + upper case, e.g.
// "metrics_listen" -> "FOVEA_METRICS_LISTEN".
std::string EnvVariableForFlag(const std::string& flag);

// Reads a variable; nullptr when unset. Tests pass their own.
using GetEnv = std::function<const char*(const char* name)>;

// For each name in `flags`, when its variable is set (empty counts as
// set), parses the value into the registered absl flag of that name.
// INVALID_ARGUMENT naming the variable when the value does not parse;
// INTERNAL when no flag has that name (a programming error). Flags before
// the failing one keep their new values.
absl::Status ApplyFlagsFromEnv(const std::vector<std::string>& flags,
                               const GetEnv& get_env);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_ENV_FLAGS_H_
