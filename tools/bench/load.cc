#include "tools/bench/load.h"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "client/channel.h"
#include "core/base/status_macros.h"
#include "core/synth/sequence.h"
#include "core/synth/synth_scene.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "fovea/v1/track.pb.h"
#include "server/convert.h"
#include "server/status_util.h"

namespace fovea::bench {
namespace {

using Clock = std::chrono::steady_clock;

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(values.size() - 1,
                            static_cast<size_t>(q * (values.size() - 1) + 0.5));
  return values[i];
}

// True when every address of `servers` (one, or a comma-separated list)
// is on loopback.
bool IsLoopback(const std::string& servers) {
  for (absl::string_view address : absl::StrSplit(servers, ',')) {
    address = absl::StripAsciiWhitespace(address);
    if (!absl::StartsWith(address, "127.") &&
        !absl::StartsWith(address, "localhost:") &&
        !absl::StartsWith(address, "[::1]:")) {
      return false;
    }
  }
  return true;
}

struct CallResult {
  grpc::StatusCode code = grpc::StatusCode::OK;
  double ms = 0;
  double first_object_ms = -1;
};

template <typename Request, typename Call>
CallResult Stream(const Request& request, double deadline_s, Call call) {
  grpc::ClientContext context;
  context.set_deadline(
      std::chrono::system_clock::now() +
      std::chrono::microseconds(static_cast<int64_t>(deadline_s * 1e6)));
  const Clock::time_point start = Clock::now();
  auto reader = call(&context, request);
  v1::SegmentResponse response;
  CallResult result;
  while (reader->Read(&response)) {
    if (response.has_object() && result.first_object_ms < 0) {
      result.first_object_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - start)
              .count();
    }
  }
  result.code = reader->Finish().error_code();
  result.ms =
      std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  return result;
}

// The frames of the drifting camera a track client sends, over and over.
constexpr int kTrackFrames = 12;

bool IsRefusal(grpc::StatusCode code) {
  return code == grpc::StatusCode::RESOURCE_EXHAUSTED ||
         code == grpc::StatusCode::UNAVAILABLE;
}

// A client's wait after a refusal, as a gRPC retry policy's: a random time
// up to the current backoff, which starts at 0.1 s and doubles up to 1 s;
// an OK call resets it.
class Backoff {
 public:
  Backoff(bool enabled, uint64_t seed) : enabled_(enabled), random_(seed) {}

  // After a call that ended with `code`: waits when it was refused (never
  // past `until`).
  void After(grpc::StatusCode code, Clock::time_point until) {
    if (!enabled_) return;
    if (!IsRefusal(code)) {
      if (code == grpc::StatusCode::OK) seconds_ = kInitial;
      return;
    }
    const double wait =
        std::uniform_real_distribution<double>(0.0, seconds_)(random_);
    seconds_ = std::min(seconds_ * 2.0, kMax);
    const Clock::time_point wake =
        Clock::now() +
        std::chrono::microseconds(static_cast<int64_t>(wait * 1e6));
    std::this_thread::sleep_until(std::min(wake, until));
  }

 private:
  static constexpr double kInitial = 0.1, kMax = 1.0;
  const bool enabled_;
  std::mt19937_64 random_;
  double seconds_ = kInitial;
};

// One Track stream: `frames` sent in turn, each after the last one's
// answer, until `until`; each answer recorded as an OK call (its round
// trip), and the stream's end as a call with its code when it was not OK
// (a refusal: the stream limits).
void TrackUntil(v1::Perception::Stub& stub,
                const std::vector<v1::TrackFrame>& frames,
                Clock::time_point until, double deadline_s,
                const std::function<void(const CallResult&)>& record) {
  grpc::ClientContext context;
  context.set_deadline(
      std::chrono::system_clock::now() +
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          until - Clock::now()) +
      std::chrono::microseconds(static_cast<int64_t>(deadline_s * 1e6)));
  const Clock::time_point opened = Clock::now();
  auto stream = stub.Track(&context);
  v1::TrackRequest options;
  options.mutable_options()->set_request_id("fovea-bench-load");
  v1::TrackResponse response;
  bool answered = false;
  if (stream->Write(options)) {
    for (size_t i = 0; Clock::now() < until; ++i) {
      v1::TrackRequest request;
      *request.mutable_frame() = frames[i % frames.size()];
      request.mutable_frame()->set_sequence(i);
      const Clock::time_point sent = Clock::now();
      if (!stream->Write(request) || !stream->Read(&response)) break;
      answered = true;
      CallResult result;
      result.ms = std::chrono::duration<double, std::milli>(Clock::now() - sent)
                      .count();
      record(result);
    }
    stream->WritesDone();
    while (stream->Read(&response)) {
    }
  }
  const grpc::Status status = stream->Finish();
  if (!status.ok()) {
    CallResult result;
    result.code = status.error_code();
    result.ms =
        answered
            ? 0.0
            : std::chrono::duration<double, std::milli>(Clock::now() - opened)
                  .count();
    record(result);
  }
}

}  // namespace

absl::StatusOr<LoadReport> RunLoad(const LoadOptions& options) {
  if (!IsLoopback(options.server)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--server must be loopback addresses (127.x, localhost, [::1]), got ",
        options.server));
  }
  if (absl::StatusOr<std::string> target =
          client::ChannelTarget(options.server);
      !target.ok()) {
    return target.status();
  }
  if (options.clients < 1 || options.requests < 1 ||
      !(options.max_seconds > 0) || !(options.deadline_seconds > 0)) {
    return absl::InvalidArgumentError(
        "--clients, --requests, --seconds and --deadline_s must be positive");
  }
  if (options.rpc != "detect" && options.rpc != "segment" &&
      options.rpc != "segment-incremental" && options.rpc != "track") {
    return absl::InvalidArgumentError(
        "--rpc must be detect, segment, segment-incremental or track");
  }
  if (options.duration_seconds < 0) {
    return absl::InvalidArgumentError("--duration_s must be >= 0");
  }
  const synth::SynthScene scene = synth::GenerateScene(options.synthetic_seed);
  const v1::Frame frame = server::ToProtoFrame(
      scene.frame.frame, server::DepthEncoding::k16UC1, 0.001);
  // Track: a drifting camera's frames, sent over and over.
  std::vector<v1::TrackFrame> track_frames;
  if (options.rpc == "track") {
    const synth::Sequence sequence = synth::GenerateSequence(
        synth::SequenceKind::kDrift, options.synthetic_seed, kTrackFrames);
    for (const synth::SequenceFrame& f : sequence.frames) {
      v1::TrackFrame wire;
      *wire.mutable_frame() = server::ToProtoFrame(
          f.frame.frame, server::DepthEncoding::k16UC1, 0.001);
      track_frames.push_back(std::move(wire));
    }
  }

  std::atomic<int> issued{0};
  std::mutex mutex;
  std::vector<CallResult> results;
  const Clock::time_point start = Clock::now();
  const Clock::time_point stop_at =
      start + std::chrono::microseconds(
                  static_cast<int64_t>(options.max_seconds * 1e6));
  // Each client its own channel and connections, as separate robots
  // would have.
  std::vector<std::unique_ptr<v1::Perception::Stub>> stubs;
  for (int i = 0; i < options.clients; ++i) {
    FOVEA_ASSIGN_OR_RETURN(
        std::shared_ptr<grpc::Channel> channel,
        client::CreateBalancedChannel(options.server, client::ClientOptions()));
    stubs.push_back(v1::Perception::NewStub(channel));
  }
  const bool fixed_time = options.duration_seconds > 0;
  const Clock::time_point end_at =
      fixed_time ? start + std::chrono::microseconds(static_cast<int64_t>(
                               options.duration_seconds * 1e6))
                 : stop_at;
  auto client = [&](int index) {
    v1::Perception::Stub* stub = stubs[index].get();
    Backoff backoff(options.backoff, static_cast<uint64_t>(index) + 1);
    const auto record = [&](const CallResult& result) {
      backoff.After(result.code, end_at);
      std::lock_guard<std::mutex> lock(mutex);
      results.push_back(result);
    };
    if (options.rpc == "track") {
      while (Clock::now() < end_at) {
        TrackUntil(*stub, track_frames, end_at, options.deadline_seconds,
                   record);
      }
      return;
    }
    while ((fixed_time || issued.fetch_add(1) < options.requests) &&
           Clock::now() < end_at) {
      CallResult result;
      if (options.rpc == "detect") {
        v1::DetectRequest request;
        *request.mutable_frame() = frame;
        grpc::ClientContext context;
        context.set_deadline(std::chrono::system_clock::now() +
                             std::chrono::microseconds(static_cast<int64_t>(
                                 options.deadline_seconds * 1e6)));
        v1::DetectResponse response;
        const Clock::time_point t = Clock::now();
        result.code = stub->Detect(&context, request, &response).error_code();
        result.ms =
            std::chrono::duration<double, std::milli>(Clock::now() - t).count();
      } else if (options.rpc == "segment") {
        v1::SegmentRequest request;
        *request.mutable_frame() = frame;
        result = Stream(request, options.deadline_seconds,
                        [&](grpc::ClientContext* c, const auto& r) {
                          return stub->Segment(c, r);
                        });
      } else {
        v1::SegmentIncrementalRequest request;
        *request.mutable_frame() = frame;
        result = Stream(request, options.deadline_seconds,
                        [&](grpc::ClientContext* c, const auto& r) {
                          return stub->SegmentIncremental(c, r);
                        });
      }
      record(result);
    }
  };
  std::vector<std::thread> threads;
  for (int i = 0; i < options.clients; ++i) threads.emplace_back(client, i);
  for (std::thread& t : threads) t.join();

  LoadReport report;
  report.calls = static_cast<int>(results.size());
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  report.throughput = report.seconds > 0 ? report.calls / report.seconds : 0;
  std::vector<double> ok_ms, first_ms, refusal_ms;
  for (const CallResult& r : results) {
    ++report.codes[std::string(
        server::GrpcCodeName(static_cast<absl::StatusCode>(r.code)))];
    if (r.code == grpc::StatusCode::OK) ok_ms.push_back(r.ms);
    if (IsRefusal(r.code)) refusal_ms.push_back(r.ms);
    if (r.first_object_ms >= 0) first_ms.push_back(r.first_object_ms);
  }
  report.ok = static_cast<int>(ok_ms.size());
  report.goodput = report.seconds > 0 ? report.ok / report.seconds : 0;
  report.refused = static_cast<int>(refusal_ms.size());
  report.refusal_p50_ms = Percentile(refusal_ms, 0.5);
  report.refusal_p99_ms = Percentile(refusal_ms, 0.99);
  report.p50_ms = Percentile(ok_ms, 0.5);
  report.p99_ms = Percentile(ok_ms, 0.99);
  report.first_object_p50_ms = Percentile(first_ms, 0.5);
  return report;
}

}  // namespace fovea::bench
