#include "tools/bench/load.h"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "client/channel.h"
#include "core/base/status_macros.h"
#include "core/synth/synth_scene.h"
#include "fovea/v1/perception.grpc.pb.h"
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
      options.rpc != "segment-incremental") {
    return absl::InvalidArgumentError(
        "--rpc must be detect, segment or segment-incremental");
  }
  const synth::SynthScene scene = synth::GenerateScene(options.synthetic_seed);
  const v1::Frame frame = server::ToProtoFrame(
      scene.frame.frame, server::DepthEncoding::k16UC1, 0.001);

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
  auto client = [&](int index) {
    v1::Perception::Stub* stub = stubs[index].get();
    while (issued.fetch_add(1) < options.requests && Clock::now() < stop_at) {
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
      std::lock_guard<std::mutex> lock(mutex);
      results.push_back(result);
    }
  };
  std::vector<std::thread> threads;
  for (int i = 0; i < options.clients; ++i) threads.emplace_back(client, i);
  for (std::thread& t : threads) t.join();

  LoadReport report;
  report.calls = static_cast<int>(results.size());
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  report.throughput = report.seconds > 0 ? report.calls / report.seconds : 0;
  std::vector<double> ok_ms, first_ms;
  for (const CallResult& r : results) {
    ++report.codes[std::string(
        server::GrpcCodeName(static_cast<absl::StatusCode>(r.code)))];
    if (r.code == grpc::StatusCode::OK) ok_ms.push_back(r.ms);
    if (r.first_object_ms >= 0) first_ms.push_back(r.first_object_ms);
  }
  report.p50_ms = Percentile(ok_ms, 0.5);
  report.p99_ms = Percentile(ok_ms, 0.99);
  report.first_object_p50_ms = Percentile(first_ms, 0.5);
  return report;
}

}  // namespace fovea::bench
