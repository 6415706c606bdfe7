#ifndef FOVEA_TOOLS_BENCH_STAGES_H_
#define FOVEA_TOOLS_BENCH_STAGES_H_

namespace fovea::bench {

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

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_STAGES_H_
