// fovea-client: calls a Fovea server from the command line.
//
//   fovea-client --server HOST:PORT health
//   fovea-client --server HOST:PORT capabilities [--json]
//   fovea-client --server HOST:PORT detect FRAME [options] [--json] [--out DIR]
//   fovea-client --server HOST:PORT segment FRAME [--method cos|ebs] ...
//   fovea-client --server HOST:PORT segment-incremental FRAME ...
// where --server may also list replicas, IP:PORT,IP:PORT,..., or name them
// all with one DNS name, dns:///NAME:PORT (client/channel.h), and
// FRAME is --color C.png --depth D.png [--fx .. --fy .. --cx .. --cy ..]
// or --pcd scene.pcd or --synthetic SEED.
//
// Exit codes: 0 success (health: SERVING), 1 health not SERVING or a local
// failure (unreadable file, cannot write --out), 2 the call failed (the gRPC
// code name and message go to stderr), 64 usage error.

#include <cstdint>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "client/cli_frame.h"
#include "client/cli_output.h"
#include "client/cli_requests.h"
#include "client/fovea_client.h"
#include "core/base/status_macros.h"
#include "proto/enum_names.h"

// The connection and the output. The request flags (the frame, detect
// options, scene, segmentation) are in cli_requests.cc.
ABSL_FLAG(std::string, server, "127.0.0.1:50051",
          "gRPC server: HOST:PORT, replicas as IP:PORT,IP:PORT,... or one "
          "DNS name for all of them, dns:///NAME:PORT; calls go round robin "
          "to the replicas whose health is SERVING and are retried on "
          "UNAVAILABLE");
ABSL_FLAG(int64_t, deadline_ms, 30000,
          "deadline of the call, milliseconds from its start");
ABSL_FLAG(std::string, tls_ca, "",
          "PEM CA certificates to trust: connect with TLS (empty: plaintext)");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM client certificate chain for mutual TLS (with --tls_key)");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(bool, wait_for_ready, false,
          "wait (within the deadline) for the server to come up instead of "
          "failing with UNAVAILABLE at once");
ABSL_FLAG(bool, json, false,
          "print responses as protobuf JSON, one object per line (per stream "
          "message)");
ABSL_FLAG(std::string, out, "",
          "directory for response JSON and PNGs (overlay, saliency maps, "
          "masks); asks the server for the master saliency map");
ABSL_FLAG(std::string, service, "",
          "health: service to check (\"\" = the server, or "
          "fovea.v1.Perception)");

namespace fovea::client {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitCallFailed = 2;
constexpr int kExitUsage = 64;  // EX_USAGE

constexpr char kUsageHead[] =
    R"(calls a Fovea perception server.

usage: fovea-client [--server SERVERS] COMMAND [flags]

SERVERS is HOST:PORT (default 127.0.0.1:50051), a list of replicas
IP:PORT,IP:PORT,... or one DNS name resolving to all of them,
dns:///NAME:PORT. Calls go round robin to the replicas that report
SERVING; one that fails with UNAVAILABLE before replying is retried on the
next. health asks one replica (the next reachable one).

commands:
)";

constexpr char kUsageTail[] = R"(
DIR holds <n>_color.png and <n>_depth.png, sent in the order of <n> (with
the intrinsics and scene flags as for FRAME; --fps F sends them as a
camera would, the server answering the freshest).

FRAME is one of
  --color C.png --depth D.png [--fx F --fy F --cx C --cy C] [--depth_scale S]
  --pcd scene.pcd        (OSD Kinect intrinsics unless given)
  --synthetic SEED       (a built-in synthetic table scene)

examples:
  fovea-client --server 127.0.0.1:50051 detect --synthetic 1 --out out/demo
  fovea-client detect --pcd learn6.pcd --saliency ph+sh+rso --extract msr --json
  fovea-client --server 10.0.0.5:50051,10.0.0.6:50051 detect --synthetic 1

exit codes: 0 ok, 1 not SERVING or a local failure, 2 the call failed (gRPC
code and message on stderr), 64 usage error. The flags: fovea-client --help)";

int Fail(int code, const absl::Status& status) {
  std::cerr << "fovea-client: " << absl::StatusCodeToString(status.code())
            << ": " << status.message() << "\n";
  return code;
}

// Exit code of a local error: bad flags are usage errors, the rest local
// failures.
int FailLocal(const absl::Status& status) {
  return Fail(status.code() == absl::StatusCode::kInvalidArgument
                  ? kExitUsage
                  : kExitFailure,
              status);
}

absl::Duration Deadline() {
  return absl::Milliseconds(absl::GetFlag(FLAGS_deadline_ms));
}

// The whole file at `path` ("" for an empty path); `flag` names it.
absl::StatusOr<std::string> ReadFileFlag(const std::string& path,
                                         const char* flag) {
  if (path.empty()) return std::string();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", flag, ": cannot read '", path, "'"));
  }
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

absl::StatusOr<std::unique_ptr<FoveaClient>> MakeClient() {
  ClientOptions options;
  options.wait_for_ready = absl::GetFlag(FLAGS_wait_for_ready);
  for (const auto& [flag, value, out] :
       {std::tuple<const char*, std::string, std::string*>{
            "tls_ca", absl::GetFlag(FLAGS_tls_ca), &options.tls_root_certs},
        {"tls_cert", absl::GetFlag(FLAGS_tls_cert), &options.tls_cert_chain},
        {"tls_key", absl::GetFlag(FLAGS_tls_key), &options.tls_private_key}}) {
    FOVEA_ASSIGN_OR_RETURN(std::string text, ReadFileFlag(value, flag));
    *out = std::move(text);
  }
  return FoveaClient::Connect(absl::GetFlag(FLAGS_server), options);
}

int RunHealth() {
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());
  absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus> status =
      (*client)->Health(absl::GetFlag(FLAGS_service), Deadline());
  if (!status.ok()) return Fail(kExitCallFailed, status.status());
  if (absl::GetFlag(FLAGS_json)) {
    grpc::health::v1::HealthCheckResponse response;
    response.set_status(*status);
    std::cout << ToJson(response) << std::endl;
  } else {
    std::cout << grpc::health::v1::HealthCheckResponse::ServingStatus_Name(
                     *status)
              << std::endl;
  }
  return *status == grpc::health::v1::HealthCheckResponse::SERVING
             ? kExitOk
             : kExitFailure;
}

int RunCapabilities() {
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());
  absl::StatusOr<fovea::v1::GetCapabilitiesResponse> capabilities =
      (*client)->GetCapabilities(Deadline());
  if (!capabilities.ok()) return Fail(kExitCallFailed, capabilities.status());
  if (absl::GetFlag(FLAGS_json)) {
    std::cout << ToJson(*capabilities) << std::endl;
  } else {
    PrintCapabilities(*capabilities, std::cout);
  }
  return kExitOk;
}

int RunDetect() {
  absl::StatusOr<fovea::v1::DetectOptions> options = DetectOptionsFromFlags(
      /*return_saliency_map=*/!absl::GetFlag(FLAGS_out).empty());
  if (!options.ok()) return Fail(kExitUsage, options.status());
  absl::StatusOr<LoadedFrame> frame = FrameFromFlags();
  if (!frame.ok()) return FailLocal(frame.status());
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());

  fovea::v1::DetectRequest request;
  request.set_request_id(RequestId());
  *request.mutable_options() = *std::move(options);
  const bool json = absl::GetFlag(FLAGS_json);
  if (!json) {
    std::cout << "detect on " << frame->description << " ("
              << frame->frame.ByteSizeLong() / 1024 << " KiB) at "
              << absl::GetFlag(FLAGS_server) << std::endl;
  }
  *request.mutable_frame() = std::move(frame->frame);

  const absl::Time start = absl::Now();
  absl::StatusOr<fovea::v1::DetectResponse> response =
      (*client)->Detect(request, Deadline());
  const absl::Duration round_trip = absl::Now() - start;
  if (!response.ok()) return Fail(kExitCallFailed, response.status());

  if (json) {
    std::cout << ToJson(*response) << std::endl;
  } else {
    PrintDetectTable(*response, round_trip, std::cout);
  }
  const std::string out = absl::GetFlag(FLAGS_out);
  if (!out.empty()) {
    absl::StatusOr<std::vector<std::string>> written =
        WriteDetectOutputs(out, *response, frame->color_bgr);
    if (!written.ok()) return Fail(kExitFailure, written.status());
    for (const std::string& path : *written)
      std::cerr << "wrote " << path << "\n";
  }
  return kExitOk;
}

int RunSegment(bool incremental) {
  absl::StatusOr<fovea::v1::DetectOptions> options = DetectOptionsFromFlags(
      /*return_saliency_map=*/!absl::GetFlag(FLAGS_out).empty());
  if (!options.ok()) return Fail(kExitUsage, options.status());
  absl::StatusOr<SegmentParameters> segment = SegmentParametersFromFlags();
  if (!segment.ok()) return Fail(kExitUsage, segment.status());
  absl::StatusOr<LoadedFrame> frame = FrameFromFlags();
  if (!frame.ok()) return FailLocal(frame.status());
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());

  const bool json = absl::GetFlag(FLAGS_json);
  const std::string out = absl::GetFlag(FLAGS_out);
  if (!json) {
    std::cout << (incremental ? "segment-incremental" : "segment") << " on "
              << frame->description << " at " << absl::GetFlag(FLAGS_server)
              << std::endl;
  }
  std::vector<fovea::v1::SegmentResponse> messages;  // kept for --out
  int message_count = 0;
  absl::Time start;
  auto on_message = [&](const fovea::v1::SegmentResponse& message) {
    ++message_count;
    if (json) {
      std::cout << ToJson(message) << std::endl;
    } else {
      std::cout << DescribeSegmentMessage(message, absl::Now() - start)
                << std::endl;
    }
    if (!out.empty()) {
      messages.push_back(message);
      if (message.has_object()) {
        absl::StatusOr<std::string> path =
            WriteObjectMask(out, message.object());
        if (path.ok()) {
          std::cerr << "wrote " << *path << "\n";
        } else {
          std::cerr << "fovea-client: " << path.status() << "\n";
        }
      }
    }
  };

  absl::Status status;
  if (incremental) {
    fovea::v1::SegmentIncrementalRequest request;
    request.set_request_id(RequestId());
    *request.mutable_frame() = std::move(frame->frame);
    *request.mutable_detect_options() = *std::move(options);
    request.set_max_objects(static_cast<uint32_t>(segment->max_objects));
    request.set_time_budget_seconds(segment->time_budget_ms / 1e3);
    *request.mutable_object_points() = segment->object_points;
    for (const auto& [u, v] : segment->seeds) {
      fovea::v1::AttentionPixel* point = request.add_attention_points();
      point->set_u(u);
      point->set_v(v);
    }
    start = absl::Now();
    status = (*client)->SegmentIncremental(request, Deadline(), on_message);
  } else {
    fovea::v1::SegmentRequest request;
    request.set_request_id(RequestId());
    *request.mutable_frame() = std::move(frame->frame);
    *request.mutable_detect_options() = *std::move(options);
    request.set_method(segment->method);
    request.set_max_objects(static_cast<uint32_t>(segment->max_objects));
    *request.mutable_object_points() = segment->object_points;
    for (const auto& [u, v] : segment->seeds) {
      fovea::v1::AttentionPixel* seed = request.add_seeds();
      seed->set_u(u);
      seed->set_v(v);
    }
    start = absl::Now();
    status = (*client)->Segment(request, Deadline(), on_message);
  }
  if (!json) {
    std::cout << absl::StrFormat(
                     "stream closed after %.1f ms, %d messages",
                     absl::ToDoubleMilliseconds(absl::Now() - start),
                     message_count)
              << std::endl;
  }
  if (!out.empty() && !messages.empty()) {
    absl::StatusOr<std::vector<std::string>> written =
        WriteSegmentOutputs(out, messages, frame->color_bgr);
    if (!written.ok()) {
      Fail(kExitFailure, written.status());
      if (status.ok()) return kExitFailure;
    } else {
      for (const std::string& path : *written)
        std::cerr << "wrote " << path << "\n";
    }
  }
  if (!status.ok()) return Fail(kExitCallFailed, status);
  return kExitOk;
}

// track: the frames of --frames as one stream; one line per processed
// frame (--json: the TrackResponse, each object with its track_id and
// mask).
int RunTrack() {
  absl::StatusOr<fovea::v1::DetectOptions> options =
      DetectOptionsFromFlags(/*return_saliency_map=*/false);
  if (!options.ok()) return Fail(kExitUsage, options.status());
  absl::StatusOr<SegmentParameters> segment = SegmentParametersFromFlags();
  if (!segment.ok()) return Fail(kExitUsage, segment.status());
  absl::StatusOr<std::vector<FrameSource>> sources = TrackFramesFromFlags();
  if (!sources.ok()) return Fail(kExitUsage, sources.status());
  absl::StatusOr<std::unique_ptr<FoveaClient>> client = MakeClient();
  if (!client.ok()) return FailLocal(client.status());

  fovea::v1::TrackOptions track;
  track.set_request_id(RequestId());
  *track.mutable_detect_options() = *std::move(options);
  track.set_max_objects(static_cast<uint32_t>(segment->max_objects));
  track.set_time_budget_seconds(segment->time_budget_ms / 1e3);
  *track.mutable_object_points() = segment->object_points;

  const bool json = absl::GetFlag(FLAGS_json);
  size_t next = 0;
  absl::Status local = absl::OkStatus();
  auto next_frame = [&]() -> std::optional<fovea::v1::TrackFrame> {
    if (next >= sources->size() || !local.ok()) return std::nullopt;
    absl::StatusOr<LoadedFrame> loaded = LoadFrame((*sources)[next]);
    if (!loaded.ok()) {
      local = loaded.status();
      return std::nullopt;
    }
    fovea::v1::TrackFrame frame;
    *frame.mutable_frame() = std::move(loaded->frame);
    frame.set_sequence(next++);
    return frame;
  };
  int responses = 0;
  auto on_response = [&](const fovea::v1::TrackResponse& response) {
    ++responses;
    if (json) {
      std::cout << ToJson(response) << std::endl;
      return;
    }
    std::string how = response.reused() ? "reused" : "segmented";
    if (response.has_segmented_region()) {
      const fovea::v1::BoundingBox& r = response.segmented_region();
      how = absl::StrFormat("segmented %dx%d at (%d, %d), the rest kept",
                            r.width(), r.height(), r.u(), r.v());
    }
    std::string line = absl::StrFormat(
        "frame %d: %d objects, %s, %.1f ms", response.sequence(),
        response.objects_size(), how, response.seconds() * 1e3);
    for (const fovea::v1::TrackedObject& o : response.objects()) {
      absl::StrAppend(
          &line, absl::StrFormat(
                     "  #%d %s", o.track_id(),
                     fovea::v1::ShortEnumName(
                         *fovea::v1::TrackState_descriptor()->FindValueByNumber(
                             o.state()))));
    }
    if (response.frames_skipped() > 0) {
      absl::StrAppend(&line, " (", response.frames_skipped(), " skipped)");
    }
    std::cout << line << std::endl;
  };
  const absl::Status status = (*client)->Track(
      track, next_frame, Deadline(), on_response, TrackFpsFromFlags());
  if (!local.ok()) return FailLocal(local);
  if (!status.ok()) return Fail(kExitCallFailed, status);
  if (!json) {
    std::cout << responses << " of " << sources->size() << " frames answered"
              << std::endl;
  }
  return kExitOk;
}

bool IsClientFlagFile(absl::string_view file) {
  return absl::StrContains(file, "client/");
}

// The commands, in the order the usage lists them; the usage and the
// unknown-command error are made from this table.
struct Command {
  absl::string_view name;
  absl::string_view arguments;  // after the name in the usage
  absl::string_view summary;
  int (*run)();
};

const std::vector<Command>& Commands() {
  static const auto* const kCommands = new std::vector<Command>{
      {"health", "", "print the serving status; exit 0 when SERVING",
       &RunHealth},
      {"capabilities", "", "what the server accepts and offers",
       &RunCapabilities},
      {"detect", "FRAME", "attention points, most salient first", &RunDetect},
      {"segment", "FRAME", "object masks, streamed as each completes",
       [] { return RunSegment(/*incremental=*/false); }},
      {"segment-incremental", "FRAME",
       "anytime incremental segmentation, streamed",
       [] { return RunSegment(/*incremental=*/true); }},
      {"track", "--frames DIR",
       "a stream of frames: objects with identities that persist", &RunTrack},
  };
  return *kCommands;
}

std::string Usage() {
  std::string usage = kUsageHead;
  for (const Command& row : Commands()) {
    std::string call = absl::StrCat("  ", row.name);
    if (!row.arguments.empty()) absl::StrAppend(&call, " ", row.arguments);
    constexpr size_t kColumn = 25;
    if (call.size() + 1 > kColumn) {
      absl::StrAppend(&usage, call, "\n", std::string(kColumn, ' '));
    } else {
      absl::StrAppend(&usage, call, std::string(kColumn - call.size(), ' '));
    }
    absl::StrAppend(&usage, row.summary, "\n");
  }
  return absl::StrCat(usage, kUsageTail);
}

}  // namespace
}  // namespace fovea::client

int main(int argc, char** argv) {
  using namespace fovea::client;  // NOLINT: main only
  const std::string usage = Usage();
  absl::SetProgramUsageMessage(usage);
  absl::FlagsUsageConfig usage_config;
  usage_config.contains_help_flags = IsClientFlagFile;
  usage_config.contains_helpshort_flags = IsClientFlagFile;
  usage_config.normalize_filename = [](absl::string_view file) {
    const size_t at = file.rfind("client/");
    return std::string(at == absl::string_view::npos ? file : file.substr(at));
  };
  absl::SetFlagsUsageConfig(usage_config);

  std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (positional.size() < 2) {
    std::cerr << "fovea-client " << usage << "\n";
    return kExitUsage;
  }
  const std::string command = positional[1];
  if (positional.size() > 2) {
    std::cerr << "fovea-client: unexpected argument \"" << positional[2]
              << "\" after " << command << "\n";
    return kExitUsage;
  }
  if (command == "help") {
    std::cout << "fovea-client " << usage << "\n";
    return kExitOk;
  }
  std::vector<absl::string_view> known;
  for (const Command& row : Commands()) {
    if (command == row.name) return row.run();
    known.push_back(row.name);
  }
  std::cerr << "fovea-client: unknown command \"" << command << "\" ("
            << absl::StrJoin(known, ", ") << ")\n";
  return kExitUsage;
}
