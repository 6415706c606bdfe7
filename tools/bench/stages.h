#ifndef FOVEA_TOOLS_BENCH_STAGES_H_
#define FOVEA_TOOLS_BENCH_STAGES_H_

#include <string>

#include "absl/status/status.h"
#include "tools/bench/bench_inputs.h"

namespace fovea::bench {

// Appends the frames of a named set to `scenes`: "osd" (FOVEA_OSD_DIR's
// learn scenes; an error without it), "pile-15" (synthetic 15-object
// piles, 8 by default), "room-640x480" or "room-1920x1080" (synthetic
// active-stereo rooms, 8 by default). `count` > 0: that many frames.
absl::Status LoadSceneSet(const std::string& set, int count, SceneList& scenes);

// fovea-bench stages [--set osd|pile-15|room-640x480|room-1920x1080]
//                    [--scenes N] [--passes N] [--threads N]
// Runs Detect, Segment (COS), SegmentIncremental (INC) and pcl-lccp, each
// from the raw wire frame with default options, on every frame of the set
// `passes` times, and prints a Markdown table of the median time of each
// stage per request (same-named stages of one request summed), with the
// time to the first object and the whole request last. `argv[1]` is
// "stages". --threads: threads per request (ParallelScope), default 1.
// Returns the process's exit code.
int RunStagesCommand(int argc, char** argv);

// fovea-bench anytime [--set ...] [--scenes N] [--passes N] [--threads N]
// The anytime curve (thesis Fig. 3.13's axes): for k = 1, 2, ..., the
// median time from the raw wire frame to SegmentIncremental's (INC) and
// Segment's (COS) k-th object, and to the whole scene; default set
// pile-15. `argv[1]` is "anytime". Returns the process's exit code.
int RunAnytimeCommand(int argc, char** argv);

// fovea-bench memory [--set ...] [--scenes N] [--passes N] [--threads N]
// Per request kind of `stages`, the largest rise of the process's peak
// resident set (VmHWM, reset before each request) over its resident set
// just before the request; default set room-640x480, 3 frames, after one
// warm-up pass. `argv[1]` is "memory". Returns the process's exit code.
int RunMemoryCommand(int argc, char** argv);

// fovea-bench digest [--set ...] [--scenes N] [--threads N]
// Per frame, a 64-bit digest of what Detect (points, master map, plane),
// Segment (COS) and SegmentIncremental (INC) return with default options
// (seeds, masks, scores), and one of the whole set: two builds, or one
// and two threads, that print the same digests give the same results.
// `argv[1]` is "digest". Returns the process's exit code.
int RunDigestCommand(int argc, char** argv);

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_STAGES_H_
