#ifndef FOVEA_TOOLS_EVAL_COMMANDS_H_
#define FOVEA_TOOLS_EVAL_COMMANDS_H_

// The commands of fovea-eval (main.cc defines the flags they read).

#include <optional>
#include <string>
#include <vector>

#include "core/frame/osd_pcd.h"
#include "core/pipeline/detect.h"

namespace fovea::eval {

// Exit statuses: a flag that does not parse, a run that failed.
inline constexpr int kUsageError = 64;
inline constexpr int kRunError = 1;

// The Detect options of the flags detect, segment and rooms share; nullopt
// (after a message on stderr) when one does not parse.
std::optional<DetectOptions> DetectOptionsFromFlags();

// The scenes of --data (an OSD-format folder; its kinds.txt, if any, names
// the kinds) or of --piles (synthetic piles from --seed); nullopt after a
// message. segment_command.cc.
std::optional<std::vector<LabelledFrame>> ScenesFromFlags();

// `flag` when set, else the environment variable `name` ("" when unset).
std::string FlagOrEnv(const std::string& flag, const char* name);

int RunDetectEval();      // detect_command.cc
int RunSegmentEval();     // segment_command.cc
int RunRoomsCommand();    // rooms_command.cc
int RunRawCommand();      // rooms_command.cc
int RunSweepCommand();    // rooms_command.cc
int RunTrackCommand();    // track_command.cc
int RunRealismCommand();  // realism_command.cc

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_COMMANDS_H_
