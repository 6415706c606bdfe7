#ifndef FOVEA_SERVER_LOG_H_
#define FOVEA_SERVER_LOG_H_

#include <string_view>

#include "absl/status/statusor.h"

namespace fovea::server {

// A tiny stderr logger. Debian 12's abseil (20220623) has no absl/log, and
// the server needs little: one line per call and a few start-up and
// shutdown lines. Thread-safe; each message is one line, written whole.
//
// Line format: "2024-05-01T12:00:00.123456Z I message" (UTC, then one
// letter for the level: D, I, W, E).

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

// "debug", "info", "warn" (or "warning"), "error". INVALID_ARGUMENT
// naming `--log_level` otherwise.
absl::StatusOr<LogLevel> ParseLogLevel(std::string_view text);

// Messages below `level` are dropped. The default is kInfo.
void SetLogLevel(LogLevel level);
bool LogEnabled(LogLevel level);

// Writes `message` (without a trailing newline) when `level` is enabled.
void Log(LogLevel level, std::string_view message);

inline void LogInfo(std::string_view message) { Log(LogLevel::kInfo, message); }
inline void LogWarn(std::string_view message) { Log(LogLevel::kWarn, message); }
inline void LogError(std::string_view message) {
  Log(LogLevel::kError, message);
}

}  // namespace fovea::server

#endif  // FOVEA_SERVER_LOG_H_
