#include "tools/bench/grpc_benchmark.h"

#include <grpcpp/grpcpp.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <iterator>
#include <memory>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/segment.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "server/convert.h"
#include "server/log.h"
#include "server/server.h"
#include "tools/bench/stage_benchmarks.h"

namespace fovea::bench {
namespace {

// Rough cost per call, milliseconds (sizes the passes, see SweepIterations).
constexpr double kGrpcDetectMs = 40.0;
constexpr double kObjectMessagesMs = 1.0;
// How long to wait for the server's warm-up.
constexpr auto kWarmUpTimeout = std::chrono::seconds(60);
constexpr auto kWarmUpPoll = std::chrono::milliseconds(10);

// The in-process server and a stub on a loopback channel to it.
struct Loopback {
  std::unique_ptr<server::FoveaServer> server;
  std::unique_ptr<v1::Perception::Stub> stub;
  std::string records;  // the recorder's folder, removed at the end
};

int& LoopbackThreads() {
  static int threads = 1;
  return threads;
}

// Whether the loopback server's flight recorder is on, and for which share
// of the calls (into a temporary folder of at most kRecordedMaxBytes).
enum class Recording { kOff, kEveryCall, kOneInTen };
constexpr Recording kRecordings[] = {Recording::kOff, Recording::kEveryCall,
                                     Recording::kOneInTen};

double RecordSample(Recording recording) {
  return recording == Recording::kOneInTen ? 0.1 : 1.0;
}

// One loopback server per recording mode.
std::unique_ptr<Loopback>& LoopbackInstance(
    Recording recording = Recording::kOff) {
  static auto* loopbacks =
      new std::unique_ptr<Loopback>[std::size(kRecordings)];
  return loopbacks[static_cast<int>(recording)];
}

constexpr int64_t kRecordedMaxBytes = int64_t{256} << 20;

absl::StatusOr<Loopback*> StartLoopback(Recording recording = Recording::kOff) {
  std::unique_ptr<Loopback>& loopback = LoopbackInstance(recording);
  if (loopback != nullptr) return loopback.get();
  server::SetLogLevel(server::LogLevel::kWarn);  // no line per call
  server::ServerConfig config;
  config.listen = "127.0.0.1:0";
  config.concurrency = 1;
  config.threads_per_request = LoopbackThreads();
  if (recording != Recording::kOff) {
    char folder[] = "/tmp/fovea-bench-records-XXXXXX";
    if (mkdtemp(folder) == nullptr) {
      return absl::InternalError("cannot make a folder for the records");
    }
    config.record_dir = folder;
    config.record_max_bytes = kRecordedMaxBytes;
    config.record_sample = RecordSample(recording);
  }
  FOVEA_ASSIGN_OR_RETURN(std::unique_ptr<server::FoveaServer> started,
                         server::FoveaServer::Start(config));
  const auto deadline = std::chrono::steady_clock::now() + kWarmUpTimeout;
  while (!started->warmed_up()) {
    if (std::chrono::steady_clock::now() > deadline) {
      return absl::DeadlineExceededError("server warm-up did not finish");
    }
    std::this_thread::sleep_for(kWarmUpPoll);
  }
  auto made = std::make_unique<Loopback>();
  made->server = std::move(started);
  made->records = config.record_dir;
  made->stub = v1::Perception::NewStub(
      grpc::CreateChannel(absl::StrCat("127.0.0.1:", made->server->port()),
                          grpc::InsecureChannelCredentials()));
  loopback = std::move(made);
  return loopback.get();
}

v1::DetectRequest MakeRequest(const BenchScene& scene,
                              const std::vector<SaliencyOp>& ops) {
  v1::DetectRequest request;
  request.set_request_id(scene.name);
  // The same bytes as `scene.raw_wire`: rgb8 and 16UC1 in the wire unit
  // (scene.frame was decoded from it, so the rounding is exact).
  *request.mutable_frame() = server::ToProtoFrame(
      scene.frame, server::DepthEncoding::k16UC1, kWireDepthScale);
  request.mutable_frame()->set_frame_id("camera");
  v1::DetectOptions& options = *request.mutable_options();
  for (const SaliencyOp op : ops) {
    v1::WeightedOperator& weighted = *options.add_saliency();
    weighted.set_op(server::ToProtoEnum(op));
    weighted.set_weight(1.0);
  }
  if (ops.empty()) return request;  // the server's defaults
  // The foundation's configuration, as BM_Detect runs it.
  options.set_pyramid(v1::PYRAMID_NONE);
  options.set_extraction(v1::EXTRACTION_MSR);
  options.set_split_at_surface_edges(false);
  options.set_max_points(DetectOptions{}.max_points);
  return request;
}

void BenchmarkGrpcDetect(benchmark::State& state, const SceneList& scenes,
                         const std::string& set_name,
                         const std::vector<SaliencyOp>& ops,
                         Recording recording = Recording::kOff) {
  absl::StatusOr<Loopback*> loopback = StartLoopback(recording);
  if (!loopback.ok()) {
    state.SkipWithError(loopback.status().ToString().c_str());
    return;
  }
  // Requests are built outside the timing; serialising them is timed.
  std::unordered_map<const BenchScene*, v1::DetectRequest> requests;
  for (const auto& scene : scenes) {
    requests.emplace(scene.get(), MakeRequest(*scene, ops));
  }
  SweepScenes(state, scenes, set_name, [&](const BenchScene& scene) {
    grpc::ClientContext context;
    v1::DetectResponse response;
    const grpc::Status status =
        (*loopback)->stub->Detect(&context, requests.at(&scene), &response);
    if (!status.ok()) {
      return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                          status.error_message());
    }
    benchmark::DoNotOptimize(response.points_size());
    return absl::OkStatus();
  });
}

// Reads a segmentation stream to its end; its status.
// Reads a stream to its end. With `first_object`, the seconds from `start`
// to the first object message (to the end when there is none) are set as
// the iteration's time (cases that UseManualTime): what a robot waits
// before it can act.
absl::Status ReadStream(
    std::unique_ptr<grpc::ClientReader<v1::SegmentResponse>> reader,
    benchmark::State* first_object = nullptr,
    std::chrono::steady_clock::time_point start = {}) {
  v1::SegmentResponse response;
  int messages = 0;
  bool timed = false;
  while (reader->Read(&response)) {
    ++messages;
    if (first_object != nullptr && !timed && response.has_object()) {
      first_object->SetIterationTime(
          std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                        start)
              .count());
      timed = true;
    }
  }
  const grpc::Status status = reader->Finish();
  benchmark::DoNotOptimize(messages);
  if (!status.ok()) {
    return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                        status.error_message());
  }
  if (first_object != nullptr &&
      !timed) {  // no object: the robot knows at the end
    first_object->SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count());
  }
  return absl::OkStatus();
}

// How much of a segmentation stream a case times.
enum class StreamTiming {
  kFirst,        // the whole call with max_objects 1
  kAll,          // the whole call, every object
  kFirstObject,  // max_objects 1, until the object message arrives
};
constexpr StreamTiming kStreamTimings[] = {
    StreamTiming::kFirst, StreamTiming::kAll, StreamTiming::kFirstObject};

const char* StreamTimingName(StreamTiming timing) {
  switch (timing) {
    case StreamTiming::kFirst:
      return "first";
    case StreamTiming::kAll:
      return "all";
    case StreamTiming::kFirstObject:
      return "first_object";
  }
  return "";
}

// One Segment call per scene with the server's default options and
// `method`, timed as `timing` says.
void BenchmarkGrpcSegment(benchmark::State& state, const SceneList& scenes,
                          const std::string& set_name,
                          v1::SegmentationMethod method, StreamTiming timing) {
  const int max_objects = timing == StreamTiming::kAll ? 0 : 1;
  absl::StatusOr<Loopback*> loopback = StartLoopback();
  if (!loopback.ok()) {
    state.SkipWithError(loopback.status().ToString().c_str());
    return;
  }
  std::unordered_map<const BenchScene*, v1::SegmentRequest> requests;
  for (const auto& scene : scenes) {
    v1::SegmentRequest request;
    request.set_request_id(scene->name);
    *request.mutable_frame() = server::ToProtoFrame(
        scene->frame, server::DepthEncoding::k16UC1, kWireDepthScale);
    request.set_method(method);
    request.set_max_objects(static_cast<uint32_t>(max_objects));
    requests.emplace(scene.get(), std::move(request));
  }
  SweepScenes(state, scenes, set_name, [&](const BenchScene& scene) {
    grpc::ClientContext context;
    const auto start = std::chrono::steady_clock::now();
    return ReadStream((*loopback)->stub->Segment(&context, requests.at(&scene)),
                      timing == StreamTiming::kFirstObject ? &state : nullptr,
                      start);
  });
}

// One SegmentIncremental call per scene with the server's defaults, timed
// as `timing` says.
void BenchmarkGrpcIncremental(benchmark::State& state, const SceneList& scenes,
                              const std::string& set_name,
                              StreamTiming timing) {
  const int max_objects = timing == StreamTiming::kAll ? 0 : 1;
  absl::StatusOr<Loopback*> loopback = StartLoopback();
  if (!loopback.ok()) {
    state.SkipWithError(loopback.status().ToString().c_str());
    return;
  }
  std::unordered_map<const BenchScene*, v1::SegmentIncrementalRequest> requests;
  for (const auto& scene : scenes) {
    v1::SegmentIncrementalRequest request;
    request.set_request_id(scene->name);
    *request.mutable_frame() = server::ToProtoFrame(
        scene->frame, server::DepthEncoding::k16UC1, kWireDepthScale);
    request.set_max_objects(static_cast<uint32_t>(max_objects));
    requests.emplace(scene.get(), std::move(request));
  }
  SweepScenes(state, scenes, set_name, [&](const BenchScene& scene) {
    grpc::ClientContext context;
    const auto start = std::chrono::steady_clock::now();
    return ReadStream(
        (*loopback)->stub->SegmentIncremental(&context, requests.at(&scene)),
        timing == StreamTiming::kFirstObject ? &state : nullptr, start);
  });
}

// Building and serialising the stream's object messages for one frame:
// what the server does for each object on its way to the client. The
// objects are COS's with the default options, cut once per scene before
// the timing.
void BenchmarkObjectMessages(benchmark::State& state, const SceneList& scenes,
                             const std::string& set_name) {
  const absl::StatusOr<LoadedModels>& models = BenchModels();
  if (!models.ok()) {
    state.SkipWithError(models.status().ToString().c_str());
    return;
  }
  std::unordered_map<const BenchScene*, std::vector<SegmentedObject>> objects;
  size_t count = 0;
  for (const auto& scene : scenes) {
    std::vector<SegmentedObject>& kept = objects[scene.get()];
    SegmentSinks sinks;
    sinks.object = [&kept](SegmentedObject object) {
      kept.push_back(std::move(object));
      return absl::OkStatus();
    };
    const absl::StatusOr<SegmentSummary> summary =
        RunSegment(scene->frame, SegmentOptions{}, models->View(), sinks);
    if (!summary.ok()) {
      state.SkipWithError(summary.status().ToString().c_str());
      return;
    }
    count += kept.size();
  }
  std::string wire;
  SweepScenes(state, scenes, set_name, [&](const BenchScene& scene) {
    for (const SegmentedObject& object : objects.at(&scene)) {
      if (!server::ToObjectMessage(object, scene.name)
               .SerializeToString(&wire)) {
        return absl::InternalError("an object message did not serialise");
      }
      benchmark::DoNotOptimize(wire);
    }
    return absl::OkStatus();
  });
  state.counters["objects_per_frame"] =
      static_cast<double>(count) / static_cast<double>(scenes.size());
}

}  // namespace

void SetGrpcThreadsPerRequest(int threads) { LoopbackThreads() = threads; }

void RegisterGrpcBenchmarks(const SceneList* scenes,
                            const std::string& set_name,
                            const std::string& suffix,
                            const SweepOptions& sweep) {
  if (scenes->empty()) return;
  std::vector<std::pair<std::string, std::vector<SaliencyOp>>> cases = {
      {"default", {}}};  // no options: the server's defaults
  for (const std::string_view channels : kDetectChannelSets) {
    cases.emplace_back(std::string(channels),
                       ParseSaliencyOps(channels).value());
  }
  for (const auto& [name, ops] : cases) {
    benchmark::RegisterBenchmark(
        absl::StrCat("BM_DetectGrpc/", AbslView(name), suffix).c_str(),
        [scenes, set_name, ops](benchmark::State& state) {
          BenchmarkGrpcDetect(state, *scenes, set_name, ops);
        })
        ->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                     kGrpcDetectMs))
        ->Unit(benchmark::kMillisecond);
  }
  // The same default Detect on a server whose flight recorder keeps every
  // call, and one that keeps one call in ten (--record_sample 0.1): the
  // recorder's cost on a call (BM_DetectGrpc/default's pairs).
  for (const auto& [name, recording] :
       {std::pair<const char*, Recording>{"BM_DetectGrpcRecorded",
                                          Recording::kEveryCall},
        {"BM_DetectGrpcSampled", Recording::kOneInTen}}) {
    benchmark::RegisterBenchmark(
        absl::StrCat(name, "/default", suffix).c_str(),
        [scenes, set_name, recording = recording](benchmark::State& state) {
          BenchmarkGrpcDetect(state, *scenes, set_name, {}, recording);
        })
        ->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                     kGrpcDetectMs))
        ->Unit(benchmark::kMillisecond);
  }
  for (const auto& [name, method] :
       {std::pair<const char*, v1::SegmentationMethod>{
            "cos", v1::SEGMENTATION_METHOD_COS},
        {"ebs", v1::SEGMENTATION_METHOD_EBS}}) {
    for (const StreamTiming timing : kStreamTimings) {
      benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(
          absl::StrCat("BM_SegmentGrpc/", name, "/", StreamTimingName(timing),
                       suffix)
              .c_str(),
          [scenes, set_name, method = method, timing](benchmark::State& state) {
            BenchmarkGrpcSegment(state, *scenes, set_name, method, timing);
          });
      b->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                    2 * kGrpcDetectMs))
          ->Unit(benchmark::kMillisecond);
      if (timing == StreamTiming::kFirstObject) b->UseManualTime();
    }
  }
  for (const StreamTiming timing : kStreamTimings) {
    benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(
        absl::StrCat("BM_SegmentIncrementalGrpc/", StreamTimingName(timing),
                     suffix)
            .c_str(),
        [scenes, set_name, timing](benchmark::State& state) {
          BenchmarkGrpcIncremental(state, *scenes, set_name, timing);
        });
    b->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                  2 * kGrpcDetectMs))
        ->Unit(benchmark::kMillisecond);
    if (timing == StreamTiming::kFirstObject) b->UseManualTime();
  }
  benchmark::RegisterBenchmark(
      absl::StrCat("BM_ObjectMessages/cos", suffix).c_str(),
      [scenes, set_name](benchmark::State& state) {
        BenchmarkObjectMessages(state, *scenes, set_name);
      })
      ->Iterations(SweepIterations(sweep, static_cast<int>(scenes->size()),
                                   kObjectMessagesMs))
      ->Unit(benchmark::kMillisecond);
}

void StopGrpcServer() {
  for (const Recording recording : kRecordings) {
    std::unique_ptr<Loopback>& loopback = LoopbackInstance(recording);
    if (loopback == nullptr) continue;
    loopback->stub.reset();
    loopback->server->Shutdown(absl::Seconds(1));
    const std::string records = loopback->records;
    loopback.reset();  // the recorder writes what it holds, then stops
    std::error_code ignored;
    if (!records.empty()) std::filesystem::remove_all(records, ignored);
  }
}

}  // namespace fovea::bench
