#ifndef FOVEA_TOOLS_BENCH_STAGES_H_
#define FOVEA_TOOLS_BENCH_STAGES_H_

#include <string>

#include "absl/status/status.h"
#include "tools/bench/bench_inputs.h"

namespace fovea::bench {

// Appends the frames of a named set to `scenes`:
//   - "osd": FOVEA_OSD_DIR's cropped learn scenes (an error without it);
//   - "osd-raw": its raw, uncropped Kinect frames (frames/);
//   - "realsense": FOVEA_REALSENSE_DIR's raw frames (an error without it);
//   - "pile-15": synthetic 15-object piles, 8 by default;
//   - "room-<sensor>-<W>x<H>[-<N>]": synthetic rooms seen by that sensor
//     (kinect_v1, active_stereo, time_of_flight), 8 by default, with N
//     objects on the table (as many as fit) when given, else 2-8;
//     "room-640x480" and "room-1920x1080" are the active stereo's.
// `count` > 0: at most that many frames of "osd" and of the synthetic
// sets (the raw real sets are used whole).
absl::Status LoadSceneSet(const std::string& set, int count, SceneList& scenes);

// fovea-bench stages [--set SET[,SET...]] [--scenes N] [--passes N]
//                    [--threads N]
// Runs Detect, Segment (COS), SegmentIncremental (INC) and pcl-lccp (its
// support removal included), each from the raw wire frame with default
// options, on every frame of each set `passes` times, and prints per set a
// Markdown table of the median time of each stage per request (same-named
// stages of one request summed), with the time to the first object and the
// whole request last. With several sets (run pass by pass in one process,
// so one run) a last table puts them side by side: each whole request
// against the first set's, the first object against the whole scene, and
// INC against pcl-lccp on the same frames. `argv[1]` is
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
