#include "tools/bench/stages.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "core/base/parallel.h"
#include "core/base/stage_clock.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/baseline/scene_segmenters.h"
#include "core/frame/frame_decode.h"
#include "core/frame/organized_cloud.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/pipeline/segment.h"
#include "core/synth/room.h"
#include "tools/bench/bench_inputs.h"
#include "tools/eval/realsense_frames.h"

namespace fovea::bench {
namespace {

using Clock = SteadyClock;

// One request's stage times, seconds, in the order they ran, same-named
// stages summed (every "segment.object" of a run is one figure).
class StageSeconds {
 public:
  double& operator[](const std::string& stage) {
    for (auto& [name, seconds] : stages_) {
      if (name == stage) return seconds;
    }
    return stages_.emplace_back(stage, 0.0).second;
  }
  const std::vector<std::pair<std::string, double>>& stages() const {
    return stages_;
  }

 private:
  std::vector<std::pair<std::string, double>> stages_;
};

void Add(const std::vector<StageTiming>& timings, StageSeconds& out) {
  for (const StageTiming& t : timings) out[t.stage] += t.seconds;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct StagesFlags {
  std::string set = "osd";
  int scenes = 0;  // 0: the set's default
  int passes = 3;
  int threads = 1;  // per request: this one and threads - 1 helpers
};

int Usage(const char* command) {
  std::fprintf(stderr,
               "usage: fovea-bench %s [--set SET[,SET...]] [--scenes N] "
               "[--passes N] [--threads N]\n  sets: osd osd-raw realsense "
               "pile-15 room-640x480 room-1920x1080 "
               "room-<kinect_v1|active_stereo|time_of_flight>-<W>x<H>[-<N>]\n",
               command);
  return 2;
}

bool ParseStagesFlags(int argc, char** argv, StagesFlags& flags) {
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--set" && has_value) {
      flags.set = argv[++i];
    } else if ((arg == "--scenes" || arg == "--passes" || arg == "--threads") &&
               has_value) {
      int value = 0;
      if (!absl::SimpleAtoi(argv[++i], &value) || value < 1) {
        std::fprintf(stderr, "fovea-bench %s: %s: expected N >= 1\n", argv[1],
                     std::string(arg).c_str());
        return false;
      }
      (arg == "--scenes"   ? flags.scenes
       : arg == "--passes" ? flags.passes
                           : flags.threads) = value;
    } else {
      std::fprintf(stderr, "fovea-bench %s: unknown argument %s\n", argv[1],
                   std::string(arg).c_str());
      return false;
    }
  }
  return true;
}

// A column of the table: a request kind, run once per frame and pass.
struct Column {
  std::string name;
  // Runs the request on the scene, appends its stage times (the whole
  // request as "total", the first object as "first_object").
  std::function<absl::Status(const BenchScene&, StageSeconds&)> run;
};

std::vector<Column> Columns(const LoadedModels& models) {
  std::vector<Column> columns;
  columns.push_back(
      {"Detect", [](const BenchScene& scene, StageSeconds& out) {
         const Clock::time_point start = Clock::now();
         FOVEA_ASSIGN_OR_RETURN(
             RgbdFrame frame, DecodeFrame(scene.raw_wire, BenchFrameLimits()));
         out["decode"] += SecondsSince(start);
         FOVEA_ASSIGN_OR_RETURN(DetectResult result,
                                RunDetect(frame, DetectOptions{}));
         Add(result.timings, out);
         out["total"] += SecondsSince(start);
         return absl::OkStatus();
       }});
  const auto segment_column = [&models](std::string name,
                                        bool incremental) -> Column {
    return {
        std::move(name),
        [&models, incremental](const BenchScene& scene, StageSeconds& out) {
          const Clock::time_point start = Clock::now();
          FOVEA_ASSIGN_OR_RETURN(
              RgbdFrame frame, DecodeFrame(scene.raw_wire, BenchFrameLimits()));
          out["decode"] += SecondsSince(start);
          double first = -1.0;
          SegmentSinks sinks;
          sinks.object = [&](SegmentedObject) {
            if (first < 0.0) first = SecondsSince(start);
            return absl::OkStatus();
          };
          absl::StatusOr<SegmentSummary> summary =
              incremental
                  ? RunSegmentIncremental(
                        frame, IncrementalOptions{},
                        models.View().IncFor(frame, SceneOptions{}), sinks)
                  : RunSegment(frame, SegmentOptions{}, models.View(), sinks);
          FOVEA_RETURN_IF_ERROR(summary.status());
          Add(summary->timings, out);
          const double total = SecondsSince(start);
          out["total"] += total;
          out["first_object"] += first < 0.0 ? total : first;
          return absl::OkStatus();
        }};
  };
  columns.push_back(segment_column("Segment (COS)", false));
  columns.push_back(segment_column("SegmentIncremental (INC)", true));
  columns.push_back(
      {"pcl-lccp", [](const BenchScene& scene, StageSeconds& out) {
         const Clock::time_point start = Clock::now();
         FOVEA_ASSIGN_OR_RETURN(
             RgbdFrame frame, DecodeFrame(scene.raw_wire, BenchFrameLimits()));
         out["decode"] += SecondsSince(start);
         Clock::time_point lap = Clock::now();
         FOVEA_ASSIGN_OR_RETURN(
             const OrganizedCloud cloud,
             BuildOrganizedCloud(frame, DetectOptions{}.normals));
         out["cloud + normals"] += SecondsSince(lap);
         lap = Clock::now();
         FOVEA_ASSIGN_OR_RETURN(SceneSegmentation segmentation,
                                SegmentSceneLccp(cloud, LccpSceneOptions{}));
         out["lccp"] += SecondsSince(lap);
         out["total"] += SecondsSince(start);
         return absl::OkStatus();
       }});
  return columns;
}

}  // namespace

absl::Status LoadSceneSet(const std::string& set, int count,
                          SceneList& scenes) {
  if (set == "osd-raw") {
    const char* dir = std::getenv("FOVEA_OSD_DIR");
    if (dir == nullptr || *dir == '\0') {
      return absl::FailedPreconditionError(
          "--set osd-raw needs FOVEA_OSD_DIR (the OSD data folder)");
    }
    return AddRawFrames(absl::StrCat(dir, "/frames"), kKinectV1Intrinsics,
                        "-raw", scenes);
  }
  if (set == "realsense") {
    const std::string dir = eval::RealSenseDir();
    if (dir.empty()) {
      return absl::FailedPreconditionError(
          "--set realsense needs FOVEA_REALSENSE_DIR (the RealSense frames' "
          "folder)");
    }
    return AddRawFrames(dir, eval::RealSenseIntrinsics(dir), "", scenes);
  }
  // room-<sensor>-<width>x<height>[-<objects>]
  const int dashes = static_cast<int>(std::count(set.begin(), set.end(), '-'));
  if (absl::StartsWith(set, "room-") && (dashes == 2 || dashes == 3)) {
    const std::vector<std::string> parts = absl::StrSplit(set, '-');
    FOVEA_ASSIGN_OR_RETURN(const synth::RoomSensor sensor,
                           synth::ParseRoomSensor(parts[1]));
    const std::vector<std::string> size = absl::StrSplit(parts[2], 'x');
    int width = 0;
    int height = 0;
    int objects = 0;
    if (size.size() != 2 || !absl::SimpleAtoi(size[0], &width) ||
        !absl::SimpleAtoi(size[1], &height) || width < 160 || width > 1920 ||
        height < 120 || height > 1080 ||
        (dashes == 3 && (!absl::SimpleAtoi(parts[3], &objects) || objects < 1 ||
                         objects > 20))) {
      return absl::InvalidArgumentError(
          absl::StrCat("--set ", set,
                       ": expected room-<sensor>-<W>x<H>[-<objects>], "
                       "160x120 to 1920x1080, 1 to 20 objects"));
    }
    std::vector<uint64_t> seeds;
    for (int s = 1; s <= (count > 0 ? count : 8); ++s) seeds.push_back(s);
    AddRoomScenes(seeds, sensor, width, height, scenes, objects);
    return absl::OkStatus();
  }
  if (set == "osd") {
    const char* dir = std::getenv("FOVEA_OSD_DIR");
    if (dir == nullptr || *dir == '\0') {
      return absl::FailedPreconditionError(
          "--set osd needs FOVEA_OSD_DIR (the OSD data folder)");
    }
    return AddOsdScenes(dir, count, scenes);
  }
  if (set == "pile-15") {
    AddPileScenes(15, count > 0 ? count : 8, 1, scenes);
    return absl::OkStatus();
  }
  if (set == "room-640x480" || set == "room-1920x1080") {
    const bool hd = set == "room-1920x1080";
    std::vector<uint64_t> seeds;
    for (int s = 1; s <= (count > 0 ? count : 8); ++s) seeds.push_back(s);
    AddRoomScenes(seeds, synth::RoomSensor::kActiveStereo, hd ? 1920 : 640,
                  hd ? 1080 : 480, scenes);
    return absl::OkStatus();
  }
  return absl::InvalidArgumentError(absl::StrCat("--set: unknown set ", set));
}

int RunStagesCommand(int argc, char** argv) {
  StagesFlags flags;
  if (!ParseStagesFlags(argc, argv, flags)) return Usage(argv[1]);
  // Several sets run in one process, pass by pass, so that their figures
  // compare within one run.
  const std::vector<std::string> set_names =
      absl::StrSplit(flags.set, ',', absl::SkipEmpty());
  std::vector<SceneList> sets(set_names.size());
  for (size_t s = 0; s < set_names.size(); ++s) {
    if (absl::Status status = LoadSceneSet(set_names[s], flags.scenes, sets[s]);
        !status.ok()) {
      std::fprintf(stderr, "fovea-bench stages: %s\n",
                   status.ToString().c_str());
      return 2;
    }
    if (sets[s].empty()) {
      std::fprintf(stderr, "fovea-bench stages: no scenes in set %s\n",
                   set_names[s].c_str());
      return 1;
    }
  }
  if (sets.empty()) return Usage(argv[1]);
  const absl::StatusOr<LoadedModels> models =
      LoadModels(FOVEA_BENCH_MODELS_DIR);
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-bench stages: %s\n",
                 models.status().ToString().c_str());
    return 1;
  }
  const std::vector<Column> columns = Columns(*models);
  ThreadPool pool(flags.threads - 1);
  const ParallelScope scope(&pool, flags.threads);
  // Per set, column and stage: one figure per request.
  using Samples = std::map<std::string, std::vector<double>>;
  std::vector<std::vector<Samples>> samples(
      sets.size(), std::vector<Samples>(columns.size()));
  std::vector<std::string> order;  // stages in first-seen order
  for (int pass = 0; pass < flags.passes; ++pass) {
    for (size_t s = 0; s < sets.size(); ++s) {
      for (size_t c = 0; c < columns.size(); ++c) {
        for (const auto& scene : sets[s]) {
          StageSeconds stages;
          if (absl::Status st = columns[c].run(*scene, stages); !st.ok()) {
            std::fprintf(stderr, "fovea-bench stages: %s on %s: %s\n",
                         columns[c].name.c_str(), scene->name.c_str(),
                         st.ToString().c_str());
            return 1;
          }
          for (const auto& [stage, seconds] : stages.stages()) {
            if (std::find(order.begin(), order.end(), stage) == order.end()) {
              order.push_back(stage);
            }
            samples[s][c][stage].push_back(seconds);
          }
        }
      }
    }
  }
  // The totals last.
  for (const char* last : {"first_object", "total"}) {
    const auto at = std::find(order.begin(), order.end(), last);
    if (at != order.end()) {
      order.erase(at);
      order.push_back(last);
    }
  }
  const auto median_ms = [&](size_t s, size_t c,
                             const std::string& stage) -> double {
    const auto found = samples[s][c].find(stage);
    return found == samples[s][c].end() ? -1.0 : 1e3 * Median(found->second);
  };
  for (size_t s = 0; s < sets.size(); ++s) {
    std::printf(
        "%s%zu %s frames x %d passes, %d thread(s) per request; medians, ms "
        "per request\n\n",
        s == 0 ? "" : "\n", sets[s].size(), set_names[s].c_str(), flags.passes,
        flags.threads);
    std::printf("| stage |");
    for (const Column& c : columns) std::printf(" %s |", c.name.c_str());
    std::printf("\n|---|");
    for (size_t c = 0; c < columns.size(); ++c) std::printf("---|");
    std::printf("\n");
    for (const std::string& stage : order) {
      std::printf("| %s |", stage.c_str());
      for (size_t c = 0; c < columns.size(); ++c) {
        const double ms = median_ms(s, c, stage);
        if (ms < 0.0) {
          std::printf(" |");
        } else {
          std::printf(" %.1f |", ms);
        }
      }
      std::printf("\n");
    }
  }
  if (sets.size() < 2) return 0;
  // The sets side by side: each whole request against the first set's,
  // and INC against pcl-lccp on the same frames.
  const auto column_of = [&](std::string_view name) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (columns[c].name == name) return c;
    }
    return columns.size();
  };
  const size_t detect = column_of("Detect");
  const size_t inc = column_of("SegmentIncremental (INC)");
  const size_t lccp = column_of("pcl-lccp");
  std::printf(
      "\nSets side by side (whole request, medians, ms; x: against %s, the "
      "first set)\n\n| set | frames | Detect | x | INC | x | INC first "
      "object | first / whole | pcl-lccp | INC / pcl-lccp |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n",
      set_names[0].c_str());
  for (size_t s = 0; s < sets.size(); ++s) {
    const double d = median_ms(s, detect, "total");
    const double i = median_ms(s, inc, "total");
    const double first = median_ms(s, inc, "first_object");
    const double l = median_ms(s, lccp, "total");
    std::printf(
        "| %s | %zu | %.1f | %.2f | %.1f | %.2f | %.1f | %.2f | %.1f | %.2f "
        "|\n",
        set_names[s].c_str(), sets[s].size(), d,
        d / median_ms(0, detect, "total"), i, i / median_ms(0, inc, "total"),
        first, first / i, l, i / l);
  }
  return 0;
}

int RunAnytimeCommand(int argc, char** argv) {
  StagesFlags flags;
  flags.set = "pile-15";
  if (!ParseStagesFlags(argc, argv, flags)) return Usage(argv[1]);
  SceneList scenes;
  if (absl::Status status = LoadSceneSet(flags.set, flags.scenes, scenes);
      !status.ok()) {
    std::fprintf(stderr, "fovea-bench anytime: %s\n",
                 status.ToString().c_str());
    return 2;
  }
  if (scenes.empty()) {
    std::fprintf(stderr, "fovea-bench anytime: no scenes in set %s\n",
                 flags.set.c_str());
    return 1;
  }
  const absl::StatusOr<LoadedModels> models =
      LoadModels(FOVEA_BENCH_MODELS_DIR);
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-bench anytime: %s\n",
                 models.status().ToString().c_str());
    return 1;
  }
  ThreadPool pool(flags.threads - 1);
  const ParallelScope scope(&pool, flags.threads);
  // Per method: [k] the times from the frame to its k-th object (k from
  // 0), one per request that got that far; and the whole requests' times.
  struct Method {
    std::string name;
    bool incremental;
    std::vector<std::vector<double>> to_object;
    std::vector<double> total;
  };
  std::vector<Method> methods = {{"INC", true, {}, {}}, {"COS", false, {}, {}}};
  for (int pass = 0; pass < flags.passes; ++pass) {
    for (Method& method : methods) {
      for (const auto& scene : scenes) {
        const Clock::time_point start = Clock::now();
        absl::StatusOr<RgbdFrame> frame =
            DecodeFrame(scene->raw_wire, BenchFrameLimits());
        int k = 0;
        SegmentSinks sinks;
        sinks.object = [&](SegmentedObject) {
          if (static_cast<int>(method.to_object.size()) <= k) {
            method.to_object.emplace_back();
          }
          method.to_object[k++].push_back(SecondsSince(start));
          return absl::OkStatus();
        };
        absl::StatusOr<SegmentSummary> summary =
            !frame.ok() ? absl::StatusOr<SegmentSummary>(frame.status())
            : method.incremental
                ? RunSegmentIncremental(
                      *frame, IncrementalOptions{},
                      models->View().IncFor(*frame, SceneOptions{}), sinks)
                : RunSegment(*frame, SegmentOptions{}, models->View(), sinks);
        if (!summary.ok()) {
          std::fprintf(stderr, "fovea-bench anytime: %s on %s: %s\n",
                       method.name.c_str(), scene->name.c_str(),
                       summary.status().ToString().c_str());
          return 1;
        }
        method.total.push_back(SecondsSince(start));
      }
    }
  }
  const size_t requests = scenes.size() * flags.passes;
  std::printf(
      "%zu %s frames x %d passes, %d thread(s) per request; median ms from "
      "the frame to its k-th object, over the requests that reached k (how "
      "many in brackets)\n\n",
      scenes.size(), flags.set.c_str(), flags.passes, flags.threads);
  std::printf("| objects k |");
  for (const Method& m : methods) std::printf(" %s |", m.name.c_str());
  std::printf("\n|---|");
  for (size_t m = 0; m < methods.size(); ++m) std::printf("---|");
  std::printf("\n");
  size_t rows = 0;
  for (const Method& m : methods) rows = std::max(rows, m.to_object.size());
  for (size_t k = 0; k < rows; ++k) {
    std::printf("| %zu |", k + 1);
    for (const Method& m : methods) {
      if (k >= m.to_object.size()) {
        std::printf(" |");
        continue;
      }
      const std::vector<double>& times = m.to_object[k];
      if (times.size() == requests) {
        std::printf(" %.1f |", 1e3 * Median(times));
      } else {
        std::printf(" %.1f (%zu) |", 1e3 * Median(times), times.size());
      }
    }
    std::printf("\n");
  }
  std::printf("| whole scene |");
  for (const Method& m : methods) std::printf(" %.1f |", 1e3 * Median(m.total));
  std::printf("\n");
  return 0;
}

namespace {

// The process's resident set now and its peak since the last reset, bytes
// (/proc/self/status: VmRSS, VmHWM); -1 when unreadable.
void ReadRss(int64_t& rss, int64_t& peak) {
  rss = peak = -1;
  std::FILE* status = std::fopen("/proc/self/status", "r");
  if (status == nullptr) return;
  char line[256];
  while (std::fgets(line, sizeof line, status) != nullptr) {
    long kb = 0;
    if (std::sscanf(line, "VmRSS: %ld kB", &kb) == 1) rss = int64_t{kb} << 10;
    if (std::sscanf(line, "VmHWM: %ld kB", &kb) == 1) peak = int64_t{kb} << 10;
  }
  std::fclose(status);
}

// Resets VmHWM to the current resident set (Linux: clear_refs 5).
bool ResetPeakRss() {
  std::FILE* refs = std::fopen("/proc/self/clear_refs", "w");
  if (refs == nullptr) return false;
  const bool ok = std::fputs("5", refs) >= 0;
  return std::fclose(refs) == 0 && ok;
}

}  // namespace

int RunMemoryCommand(int argc, char** argv) {
  StagesFlags flags;
  flags.set = "room-640x480";
  flags.passes = 1;
  if (!ParseStagesFlags(argc, argv, flags)) return Usage(argv[1]);
  if (flags.scenes == 0) flags.scenes = 3;
  SceneList scenes;
  if (absl::Status status = LoadSceneSet(flags.set, flags.scenes, scenes);
      !status.ok()) {
    std::fprintf(stderr, "fovea-bench memory: %s\n", status.ToString().c_str());
    return 2;
  }
  const absl::StatusOr<LoadedModels> models =
      LoadModels(FOVEA_BENCH_MODELS_DIR);
  if (!models.ok() || scenes.empty()) {
    std::fprintf(
        stderr, "fovea-bench memory: %s\n",
        models.ok() ? "no scenes" : models.status().ToString().c_str());
    return 1;
  }
  // Blocks of 64 KiB and more are mapped and unmapped one by one, and the
  // heap is trimmed before each request: what a request holds at its peak
  // is then resident, instead of reusing what an earlier one freed.
  mallopt(M_MMAP_THRESHOLD, 64 << 10);
  mallopt(M_TRIM_THRESHOLD, 0);
  ThreadPool pool(flags.threads - 1);
  const ParallelScope scope(&pool, flags.threads);
  const std::vector<Column> columns = Columns(*models);
  std::printf(
      "%zu %s frames, %d thread(s) per request; per request kind, the "
      "largest rise of the peak resident set over the resident set just "
      "before the request (models loaded, frames in memory), MB\n\n",
      scenes.size(), flags.set.c_str(), flags.threads);
  std::printf(
      "| request | peak rise, MB | resident before, MB |\n|---|---|---|\n");
  for (const Column& column : columns) {
    int64_t worst = 0, before_worst = 0;
    std::string failed;
    // A first pass warms the allocator and the lazily built tables up.
    for (int pass = 0; pass < 1 + flags.passes && failed.empty(); ++pass) {
      for (const auto& scene : scenes) {
        malloc_trim(0);
        int64_t before = 0, peak = 0;
        ReadRss(before, peak);
        if (!ResetPeakRss()) {
          std::fprintf(stderr,
                       "fovea-bench memory: cannot reset the peak RSS "
                       "(/proc/self/clear_refs)\n");
          return 1;
        }
        StageSeconds stages;
        if (absl::Status s = column.run(*scene, stages); !s.ok()) {
          failed = s.ToString();  // a peer that cannot take the frame
          break;
        }
        int64_t after = 0;
        ReadRss(after, peak);
        if (pass > 0 && peak - before > worst) {
          worst = peak - before;
          before_worst = before;
        }
      }
    }
    if (!failed.empty()) {
      std::printf("| %s | failed: %s | |\n", column.name.c_str(),
                  failed.c_str());
      continue;
    }
    std::printf("| %s | %.1f | %.1f |\n", column.name.c_str(),
                worst / 1048576.0, before_worst / 1048576.0);
  }
  return 0;
}

}  // namespace fovea::bench
