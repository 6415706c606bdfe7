// fovea-server: the Fovea perception service over gRPC.

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/reflection.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/base/memory_reuse.h"
#include "core/base/parallel.h"
#include "server/capabilities.h"
#include "server/descriptors.h"
#include "server/env_flags.h"
#include "server/log.h"
#include "server/server.h"

namespace {

int Cores() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

}  // namespace

ABSL_FLAG(std::string, listen, "0.0.0.0:50051",
          "host:port of the gRPC server. All interfaces by default, so a "
          "robot (or another container) can reach it; use "
          "127.0.0.1:50051 to serve this machine only.");
ABSL_FLAG(std::string, metrics_listen, "127.0.0.1:9464",
          "host:port of the Prometheus endpoint (GET /metrics); empty "
          "disables it. Loopback by default; use 0.0.0.0:9464 for a scraper "
          "on another host or container.");
ABSL_FLAG(int, concurrency, Cores(),
          "Frames computed at once (worker threads); default: the number of "
          "cores.");
ABSL_FLAG(int, threads_per_request, 0,
          "Threads one frame may use (stages split by rows, filters or "
          "surfaces); 0: cores / concurrency. The helper threads are shared "
          "by all workers and at most cores - concurrency, so the threads "
          "computing at once never outnumber the cores.");
ABSL_FLAG(int, queue, 2 * Cores(),
          "Frames waiting for a worker; beyond it calls fail at once with "
          "RESOURCE_EXHAUSTED. Default: twice the number of cores.");
ABSL_FLAG(int, max_message_bytes, 0,
          "Largest request accepted, bytes. 0: the largest raw frame "
          "--max_width x --max_height allows (rgb8 + 32FC1, packed rows) "
          "and 1 MiB: 15.5 MiB at 1920x1080.");
ABSL_FLAG(int, memory_quota_mb,
          static_cast<int>(fovea::server::kDefaultMemoryQuotaBytes >> 20),
          "Memory gRPC may use for requests it receives and buffers "
          "(resource quota), MiB; calls beyond it are refused.");
ABSL_FLAG(uint32_t, max_width, fovea::FrameLimits{}.max_width,
          "Widest frame accepted, pixels; wider frames are INVALID_ARGUMENT.");
ABSL_FLAG(uint32_t, max_height, fovea::FrameLimits{}.max_height,
          "Tallest frame accepted, pixels; taller frames are "
          "INVALID_ARGUMENT.");
ABSL_FLAG(double, grace_period_s, 10.0,
          "On SIGTERM/SIGINT: seconds in-flight calls get to finish before "
          "they are cancelled.");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM certificate chain of the gRPC port; with --tls_key the port "
          "speaks TLS only. Empty: plaintext (fine on loopback).");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert.");
ABSL_FLAG(std::string, tls_client_ca, "",
          "PEM CA certificates: when given, every client must present a "
          "certificate they signed (mutual TLS).");
ABSL_FLAG(bool, reflection, true,
          "Serve gRPC server reflection (grpcurl and grpc_cli list and call "
          "the services without the .proto files); false turns it off.");
ABSL_FLAG(double, drain_delay_s, 1.0,
          "On SIGTERM/SIGINT: seconds health says NOT_SERVING while calls "
          "are still served (so load balancers move away first); then new "
          "calls are refused and in-flight ones get --grace_period_s.");
ABSL_FLAG(double, max_connection_age_s, 300.0,
          "Seconds after which a client connection is asked to reconnect "
          "(gRPC GOAWAY, +-10 % jitter), so clients re-resolve DNS and "
          "spread over replicas added since; 0 keeps connections forever.");
ABSL_FLAG(double, max_connection_age_grace_s,
          fovea::server::ServerConfig{}.max_connection_age_grace_s,
          "Seconds calls in flight on such a connection get to finish: a "
          "day by default, as a Track stream is a robot's session (unary "
          "calls and new streams move to the new connection at once).");
ABSL_FLAG(double, stream_stall_timeout_s,
          fovea::server::ServerConfig{}.stream_stall_timeout_s,
          "A Segment stream whose client takes no message for this long "
          "while results wait for it is cancelled and its worker freed.");
ABSL_FLAG(int, max_track_streams,
          fovea::server::ServerConfig{}.max_track_streams,
          "Track streams open at once, from all clients; a stream beyond is "
          "RESOURCE_EXHAUSTED.");
ABSL_FLAG(int, max_track_streams_per_peer,
          fovea::server::ServerConfig{}.max_track_streams_per_peer,
          "Track streams open at once from one client address.");
ABSL_FLAG(double, track_idle_timeout_s,
          fovea::server::ServerConfig{}.track_idle_timeout_s,
          "A Track stream whose client sent nothing (no frame) for this long "
          "is closed (CANCELLED).");
ABSL_FLAG(double, handshake_timeout_s,
          fovea::server::ServerConfig{}.handshake_timeout_s,
          "A connection that has not completed the HTTP/2 (or TLS) "
          "handshake within this many seconds is closed.");
ABSL_FLAG(
    std::string, models_dir, fovea::server::ServerConfig{}.models_dir,
    "Folder of the trained models (cos_svm.txt, ...; see models/README.md). "
    "The server does not start without them.");
ABSL_FLAG(std::string, log_level, "info", "debug, info, warn or error.");
ABSL_FLAG(std::string, record_dir, "",
          "Flight recorder: keep recorded calls (frames as PNG, requests and "
          "responses as JSON) in this folder, for fovea-eval replay. Empty: "
          "off.");
ABSL_FLAG(int, record_max_mb, 1024,
          "The flight recorder's files never take more than this many MiB: "
          "the oldest records go first.");
ABSL_FLAG(double, record_sample, 1.0,
          "The share of calls the flight recorder keeps, (0, 1]: 0.1 keeps "
          "every tenth.");

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(
      "Fovea perception service: attention points (Detect) and object "
      "masks (Segment, SegmentIncremental) from RGB-D frames over gRPC "
      "(fovea.v1.Perception; health: grpc.health.v1; server reflection "
      "on).\n"
      "Usage: fovea-server [--listen=HOST:PORT] "
      "[--metrics_listen=HOST:PORT] [--concurrency=N] [--queue=N] ...\n"
      "Every flag can also come from the environment: FOVEA_LISTEN, "
      "FOVEA_METRICS_LISTEN, FOVEA_MODELS_DIR, ... (the flag's name in "
      "upper case); the command line wins.\n"
      "SIGTERM or SIGINT: health NOT_SERVING, stop accepting, let calls "
      "finish within --grace_period_s, exit 0.");
  // List this program's flags in --help, not those of linked libraries.
  absl::FlagsUsageConfig usage;
  usage.contains_help_flags = [](absl::string_view file) {
    return absl::StrContains(file, "server/main.cc");
  };
  usage.contains_helpshort_flags = usage.contains_help_flags;
  absl::SetFlagsUsageConfig(usage);

  using fovea::server::LogError;
  using fovea::server::LogInfo;
  // Before the command line, so that it wins.
  // Every flag defined in this file, each settable from the environment:
  // a new flag is its ABSL_FLAG alone.
  std::vector<std::string> server_flags;
  for (const auto& [name, flag] : absl::GetAllFlags()) {
    if (usage.contains_help_flags(flag->Filename())) {
      server_flags.emplace_back(name);
    }
  }
  std::sort(server_flags.begin(), server_flags.end());
  const absl::Status from_env = fovea::server::ApplyFlagsFromEnv(
      server_flags, [](const char* name) { return std::getenv(name); });
  if (!from_env.ok()) {
    LogError(from_env.ToString());
    return 2;
  }
  absl::ParseCommandLine(argc, argv);

  absl::StatusOr<fovea::server::LogLevel> level =
      fovea::server::ParseLogLevel(absl::GetFlag(FLAGS_log_level));
  if (!level.ok()) {
    LogError(level.status().ToString());
    return 2;
  }
  fovea::server::SetLogLevel(*level);
  const double grace_s = absl::GetFlag(FLAGS_grace_period_s);
  if (!(grace_s >= 0.0)) {
    LogError(absl::StrCat("--grace_period_s: ", grace_s, " is negative"));
    return 2;
  }

  // Block the stop signals in every thread (threads inherit the mask, so
  // this comes before any is started); main waits for them with sigwait,
  // so nothing runs inside a signal handler.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  // OpenCV's loops run on the request's threads (ParallelScope), not on a
  // pool of OpenCV's own with one thread per core beside ours.
  fovea::UseParallelScopesInOpenCv();
  // A frame's large blocks stay mapped for the next one.
  fovea::ReuseFreedMemory();
  LogInfo(fovea::server::RaiseDescriptorLimit());
  fovea::server::ServerConfig config;
  config.listen = absl::GetFlag(FLAGS_listen);
  config.metrics_listen = absl::GetFlag(FLAGS_metrics_listen);
  config.concurrency = absl::GetFlag(FLAGS_concurrency);
  config.queue = absl::GetFlag(FLAGS_queue);
  config.threads_per_request = absl::GetFlag(FLAGS_threads_per_request);
  config.max_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  config.memory_quota_bytes = int64_t{absl::GetFlag(FLAGS_memory_quota_mb)}
                              << 20;
  config.limits.max_width = absl::GetFlag(FLAGS_max_width);
  config.limits.max_height = absl::GetFlag(FLAGS_max_height);
  config.max_connection_age_s = absl::GetFlag(FLAGS_max_connection_age_s);
  config.max_connection_age_grace_s =
      absl::GetFlag(FLAGS_max_connection_age_grace_s);
  config.stream_stall_timeout_s = absl::GetFlag(FLAGS_stream_stall_timeout_s);
  config.max_track_streams = absl::GetFlag(FLAGS_max_track_streams);
  config.max_track_streams_per_peer =
      absl::GetFlag(FLAGS_max_track_streams_per_peer);
  config.track_idle_timeout_s = absl::GetFlag(FLAGS_track_idle_timeout_s);
  config.handshake_timeout_s = absl::GetFlag(FLAGS_handshake_timeout_s);
  config.drain_delay_s = absl::GetFlag(FLAGS_drain_delay_s);
  config.reflection = absl::GetFlag(FLAGS_reflection);
  config.tls_cert = absl::GetFlag(FLAGS_tls_cert);
  config.tls_key = absl::GetFlag(FLAGS_tls_key);
  config.tls_client_ca = absl::GetFlag(FLAGS_tls_client_ca);
  config.models_dir = absl::GetFlag(FLAGS_models_dir);
  config.record_dir = absl::GetFlag(FLAGS_record_dir);
  config.record_max_bytes = int64_t{absl::GetFlag(FLAGS_record_max_mb)} << 20;
  config.record_sample = absl::GetFlag(FLAGS_record_sample);

  absl::StatusOr<std::unique_ptr<fovea::server::FoveaServer>> server =
      fovea::server::FoveaServer::Start(config);
  if (!server.ok()) {
    LogError(server.status().ToString());
    return server.status().code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
  }

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  LogInfo(absl::StrCat("received ", strsignal(signal_number)));
  (*server)->Shutdown(absl::Seconds(grace_s));
  server->reset();
  LogInfo("stopped");
  return 0;
}
