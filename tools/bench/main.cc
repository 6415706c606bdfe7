// fovea-bench: Google Benchmark cases for the stages of Detect on 640x480
// frames, one core.
//
//   fovea-bench [--passes=N] [--osd_scenes=N] [--threads=N]
//               [--benchmark_* flags]
//   fovea-bench stages [--set osd|pile-15|room-640x480|room-1920x1080]
//                      [--scenes N] [--passes N] [--threads N]
//                    (median time of every stage of Detect, Segment,
//                    SegmentIncremental and pcl-lccp, as a Markdown table)
//   fovea-bench anytime [same flags; default --set pile-15]
//                    (median time to the k-th object of INC and COS)
//   fovea-bench memory [same flags; default --set room-640x480]
//                    (each request kind's peak resident memory, MB)
//   fovea-bench digest [same flags; default --set osd]
//                    (a digest of each frame's Detect, COS and INC results:
//                    equal digests, equal results)
//   fovea-bench load --server 127.0.0.1:PORT --clients C --requests N
//                    [--seconds S]
//                    [--rpc detect|segment|segment-incremental|track]
//                    [--duration_s S] [--backoff true|false]
//                    (closed-loop load on a running server, loopback only:
//                    throughput, goodput (OK calls/s), p50/p99 latency,
//                    time to first object, refusals and their latency,
//                    calls per status code; --duration_s runs for a fixed
//                    time instead of N calls; --backoff makes a refused
//                    client wait as a gRPC retry policy would; --server may
//                    list replicas, 127.0.0.1:P1,127.0.0.1:P2, to load
//                    them round robin)
//
// Inputs: synthetic scenes (core/synth, seeds kSynthSeeds) and, when
// FOVEA_OSD_DIR names the OSD data (learn/learn*.pcd), the same cases on
// the real scenes with an "/osd" suffix. Each iteration handles one frame,
// round-robin over the set, and a repetition is a whole number of passes
// over it (see SweepOptions), so a case's time is the mean per frame over
// the set and the reported median is over repetitions. Defaults
// --benchmark_repetitions=5 --benchmark_report_aggregates_only=true come
// before the caller's flags, which override them.
//   --passes=N      passes over the scene set per repetition (default: as
//                   many as make a repetition last about 0.5 s)
//   --osd_scenes=N  use only the first N OSD scenes (default: all 45)

#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "core/base/memory_reuse.h"
#include "core/base/parallel.h"
#include "tools/bench/bench_inputs.h"
#include "tools/bench/stage_benchmarks.h"
#include "tools/bench/stages.h"
#ifdef FOVEA_BENCH_GRPC
#include "tools/bench/grpc_benchmark.h"
#include "tools/bench/load.h"
#endif

namespace {

using fovea::bench::SceneList;
using fovea::bench::SweepOptions;

// Synthetic scenes timed; GenerateScene gives 2-6 objects for 1..20.
constexpr uint64_t kSynthSeeds[] = {1, 2, 3, 4};
// Synthetic rooms timed, from an active-stereo camera.
constexpr uint64_t kRoomSeeds[] = {1, 2, 3, 4, 5, 6, 7, 8};

constexpr const char* kDefaultFlags[] = {
    "--benchmark_repetitions=5",
    "--benchmark_report_aggregates_only=true",
};

struct BenchFlags {
  SweepOptions sweep;
  int osd_scenes = 0;  // 0: all
  int threads = 1;     // per case (and per loopback request)
};

// Takes "--name=N" when `arg` is that flag; false otherwise. Exits on a
// malformed value.
bool TakeIntFlag(std::string_view arg, std::string_view name, int& value) {
  const std::string prefix =
      absl::StrCat("--", absl::string_view(name.data(), name.size()), "=");
  if (arg.substr(0, prefix.size()) != prefix) return false;
  const std::string_view text = arg.substr(prefix.size());
  if (!absl::SimpleAtoi(absl::string_view(text.data(), text.size()), &value) ||
      value < 0) {
    std::fprintf(stderr, "fovea-bench: %s: expected a whole number >= 0\n",
                 std::string(arg).c_str());
    std::exit(2);
  }
  return true;
}

// Removes fovea-bench's own flags from `args` and puts the default
// benchmark flags right after the program name.
BenchFlags ParseFlags(int argc, char** argv, std::vector<char*>& args) {
  BenchFlags flags;
  args.push_back(argv[0]);
  for (const char* flag : kDefaultFlags) {
    args.push_back(const_cast<char*>(flag));
  }
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (TakeIntFlag(arg, "passes", flags.sweep.passes) ||
        TakeIntFlag(arg, "osd_scenes", flags.osd_scenes) ||
        TakeIntFlag(arg, "threads", flags.threads)) {
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      std::printf(
          "fovea-bench: Detect stage benchmarks on 640x480 frames, one core.\n"
          "  --passes=N      passes over the scene set per repetition\n"
          "                  (default: enough for about 0.5 s)\n"
          "  --osd_scenes=N  first N OSD scenes only (default: all)\n"
          "  --threads=N     threads per case and per loopback request\n"
          "                  (default 1)\n"
          "  FOVEA_OSD_DIR   OSD data folder; adds the \"/osd\" cases\n"
          "Defaults before your flags: --benchmark_repetitions=5 "
          "--benchmark_report_aggregates_only=true\n\n");
    }
    args.push_back(argv[i]);
  }
  args.push_back(nullptr);
  return flags;
}

}  // namespace

#ifdef FOVEA_BENCH_GRPC
// `fovea-bench load --server ADDR --clients C --requests N --seconds S
// --rpc detect|segment|segment-incremental|track [--deadline_s D]
// [--duration_s S] [--backoff true|false]`.
int RunLoadCommand(int argc, char** argv) {
  fovea::bench::LoadOptions options;
  if (argc % 2 != 0) {  // "fovea-bench load" and flag-value pairs
    std::fprintf(stderr,
                 "usage: fovea-bench load --server 127.0.0.1:PORT --clients C "
                 "--requests N [--seconds S] "
                 "[--rpc detect|segment|segment-incremental|track] "
                 "[--deadline_s D] [--duration_s S] [--backoff true|false]\n");
    return argc == 3 && (std::string_view(argv[2]) == "--help" ||
                         std::string_view(argv[2]) == "-h")
               ? 0
               : 2;
  }
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const std::string value = argv[i + 1];
    int n = 0;
    double x = 0;
    if (flag == "--server") {
      options.server = value;
    } else if (flag == "--rpc") {
      options.rpc = value;
    } else if (flag == "--clients" && absl::SimpleAtoi(value, &n)) {
      options.clients = n;
    } else if (flag == "--requests" && absl::SimpleAtoi(value, &n)) {
      options.requests = n;
    } else if (flag == "--seconds" && absl::SimpleAtod(value, &x)) {
      options.max_seconds = x;
    } else if (flag == "--deadline_s" && absl::SimpleAtod(value, &x)) {
      options.deadline_seconds = x;
    } else if (flag == "--duration_s" && absl::SimpleAtod(value, &x)) {
      options.duration_seconds = x;
    } else if (flag == "--backoff" && (value == "true" || value == "false")) {
      options.backoff = value == "true";
    } else {
      std::fprintf(stderr, "fovea-bench load: bad flag %s %s\n", flag.c_str(),
                   value.c_str());
      return 2;
    }
  }
  const absl::StatusOr<fovea::bench::LoadReport> report =
      fovea::bench::RunLoad(options);
  if (!report.ok()) {
    std::fprintf(stderr, "fovea-bench load: %s\n",
                 report.status().ToString().c_str());
    return 2;
  }
  std::printf(
      "load %s on %s: %d clients, %d calls in %.2f s: %.1f calls/s, p50 %.1f "
      "ms, p99 %.1f ms",
      options.rpc.c_str(), options.server.c_str(), options.clients,
      report->calls, report->seconds, report->throughput, report->p50_ms,
      report->p99_ms);
  if (report->first_object_p50_ms > 0) {
    std::printf(", first object p50 %.1f ms", report->first_object_p50_ms);
  }
  std::printf(
      "\ngoodput %.1f OK calls/s (%d OK), %d refused, refusal p50 %.2f ms, "
      "p99 %.2f ms",
      report->goodput, report->ok, report->refused, report->refusal_p50_ms,
      report->refusal_p99_ms);
  std::printf("\ncodes:");
  for (const auto& [code, count] : report->codes) {
    std::printf(" %s %d", code.c_str(), count);
  }
  std::printf("\n");
  return 0;
}
#endif

int main(int argc, char** argv) {
  // OpenCV's loops follow the ParallelScope: one core without one.
  fovea::UseParallelScopesInOpenCv();
  // As fovea-server does (`memory` sets its own allocation rules).
  fovea::ReuseFreedMemory();
  if (argc > 1 && std::string_view(argv[1]) == "stages") {
    return fovea::bench::RunStagesCommand(argc, argv);
  }
  if (argc > 1 && std::string_view(argv[1]) == "anytime") {
    return fovea::bench::RunAnytimeCommand(argc, argv);
  }
  if (argc > 1 && std::string_view(argv[1]) == "memory") {
    return fovea::bench::RunMemoryCommand(argc, argv);
  }
  if (argc > 1 && std::string_view(argv[1]) == "digest") {
    return fovea::bench::RunDigestCommand(argc, argv);
  }
#ifdef FOVEA_BENCH_GRPC
  if (argc > 1 && std::string_view(argv[1]) == "load") {
    return RunLoadCommand(argc, argv);
  }
#endif
  std::vector<char*> args;
  const BenchFlags flags = ParseFlags(argc, argv, args);
  int bench_argc = static_cast<int>(args.size()) - 1;
  benchmark::Initialize(&bench_argc, args.data());
  if (benchmark::ReportUnrecognizedArguments(bench_argc, args.data())) {
    return 2;
  }

  // Registered cases keep pointers to these: they live until the end.
  static SceneList synthetic;
  static SceneList osd;
  fovea::bench::AddSyntheticScenes(
      std::vector<uint64_t>(std::begin(kSynthSeeds), std::end(kSynthSeeds)),
      synthetic);
  const char* osd_dir = std::getenv("FOVEA_OSD_DIR");
  if (osd_dir != nullptr && *osd_dir != '\0') {
    std::fprintf(stderr, "fovea-bench: loading OSD scenes from %s\n", osd_dir);
    const absl::Status status =
        fovea::bench::AddOsdScenes(osd_dir, flags.osd_scenes, osd);
    if (!status.ok()) {
      std::fprintf(stderr, "fovea-bench: no OSD cases: %s\n",
                   status.ToString().c_str());
    }
  }
  benchmark::AddCustomContext("synthetic_frames",
                              std::to_string(synthetic.size()));
  benchmark::AddCustomContext("osd_frames", std::to_string(osd.size()));
  benchmark::AddCustomContext("opencv_threads",
                              std::to_string(cv::getNumThreads()));

  // Whole frames of four kinds in one run: uncropped rooms from an
  // active-stereo camera at 640x480 and at 1280x720 (the same seeds), and
  // the cropped OSD scenes.
  static SceneList rooms640;
  static SceneList rooms1280;
  const std::vector<uint64_t> room_seeds(std::begin(kRoomSeeds),
                                         std::end(kRoomSeeds));
  fovea::bench::AddRoomScenes(
      room_seeds, fovea::synth::RoomSensor::kActiveStereo, 640, 480, rooms640);
  fovea::bench::AddRoomScenes(room_seeds,
                              fovea::synth::RoomSensor::kActiveStereo, 1280,
                              720, rooms1280);
  // ... and dense piles of 15 objects (seeds from 1, fovea-eval's held-out
  // piles), Detect and INC to the last object.
  static SceneList piles15;
  fovea::bench::AddPileScenes(15, 8, 1, piles15);
  fovea::bench::RegisterFrameCases({{"room-640x480", &rooms640},
                                    {"room-1280x720", &rooms1280},
                                    {"osd", &osd},
                                    {"pile-15", &piles15}},
                                   flags.sweep);

  // Synthetic cases first, then the OSD ones; in each, the gRPC cases come
  // right after the in-process Detect cases they compare with.
  for (const auto& [scenes, set_name, suffix] :
       {std::tuple<const SceneList*, std::string, std::string>{&synthetic,
                                                               "synthetic", ""},
        {&osd, "OSD", "/osd"}}) {
    fovea::bench::RegisterStageBenchmarks(scenes, set_name, suffix,
                                          flags.sweep);
#ifdef FOVEA_BENCH_GRPC
    fovea::bench::RegisterGrpcBenchmarks(scenes, set_name, suffix, flags.sweep);
#endif
  }

  if (flags.threads < 1) {
    std::fprintf(stderr, "fovea-bench: --threads: expected N >= 1\n");
    return 2;
  }
  benchmark::AddCustomContext("threads_per_case",
                              std::to_string(flags.threads));
#ifdef FOVEA_BENCH_GRPC
  fovea::bench::SetGrpcThreadsPerRequest(flags.threads);
#endif
  fovea::ThreadPool pool(flags.threads - 1);
  const fovea::ParallelScope scope(&pool, flags.threads);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
#ifdef FOVEA_BENCH_GRPC
  fovea::bench::StopGrpcServer();
#endif
  return 0;
}
