#include "server/server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/impl/server_builder_option.h>
#include <grpcpp/impl/server_builder_plugin.h>
#include <grpcpp/resource_quota.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "core/base/status_macros.h"
#include "core/base/tsan.h"
#include "core/synth/synth_scene.h"
#include "grpc/health/v1/health.pb.h"
#include "server/accept_guard.h"
#include "server/capabilities.h"
#include "server/clock.h"
#include "server/convert.h"
#include "server/descriptors.h"
#include "server/handle_detect.h"
#include "server/log.h"

namespace fovea::server {
namespace {

// The names health reports on: the whole server and the service.
constexpr const char* kHealthNames[] = {"", "fovea.v1.Perception"};

// Warm-up frame: the synthetic scene of this seed, rendered at
// 1 / kWarmUpDownscale of the Kinect's 640x480 (320x240: small, yet large
// enough for core's pixel-sized defaults, e.g. MSR's smallest region, to
// yield points, so every stage runs).
// Largest --max_connection_age_s and grace: gRPC takes milliseconds as an
// int; a day is plenty.
constexpr double kMaxConnectionAgeS = 86400.0;

constexpr uint64_t kWarmUpSeed = 1;
constexpr int kWarmUpDownscale = 2;

// A small synthetic scene as a wire request, default options.
v1::DetectRequest WarmUpRequest() {
  synth::SceneSpec spec =
      synth::RandomSceneSpec(kWarmUpSeed, synth::RandomSceneOptions{});
  const double s = 1.0 / kWarmUpDownscale;
  spec.width /= kWarmUpDownscale;
  spec.height /= kWarmUpDownscale;
  spec.intrinsics.fx *= s;
  spec.intrinsics.fy *= s;
  // Pixel centres: x' + 0.5 = (x + 0.5) * s.
  spec.intrinsics.cx = (spec.intrinsics.cx + 0.5) * s - 0.5;
  spec.intrinsics.cy = (spec.intrinsics.cy + 0.5) * s - 0.5;
  synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, kWarmUpSeed);
  v1::DetectRequest request;
  request.set_request_id("warm-up");
  *request.mutable_frame() =
      ToProtoFrame(scene.frame.frame, DepthEncoding::k32FC1);
  return request;
}

// Removes the reflection plugin from a builder: linking gRPC's reflection
// library registers it for every server of the process.
class WithoutReflection final : public grpc::ServerBuilderOption {
 public:
  void UpdateArguments(grpc::ChannelArguments*) override {}
  void UpdatePlugins(std::vector<std::unique_ptr<grpc::ServerBuilderPlugin>>*
                         plugins) override {
    plugins->erase(
        std::remove_if(plugins->begin(), plugins->end(),
                       [](const std::unique_ptr<grpc::ServerBuilderPlugin>& p) {
                         return p->name() == "proto_server_reflection";
                       }),
        plugins->end());
  }
};

// The whole file at `path`; `flag` names it in the error.
absl::StatusOr<std::string> ReadPem(const std::string& path, const char* flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": cannot read '", path, "'"));
  }
  std::string text((std::istreambuf_iterator<char>(in)),
                   std::istreambuf_iterator<char>());
  if (text.find("-----BEGIN ") == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": '", path, "' is not a PEM file"));
  }
  return text;
}

// Plaintext, TLS or mutual TLS (ServerConfig::tls_*).
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> ServerCredentials(
    const ServerConfig& config) {
  if (config.tls_cert.empty() && config.tls_key.empty()) {
    if (!config.tls_client_ca.empty()) {
      return absl::InvalidArgumentError(
          "--tls_client_ca: needs --tls_cert and --tls_key");
    }
    return grpc::InsecureServerCredentials();
  }
  if (config.tls_cert.empty() || config.tls_key.empty()) {
    return absl::InvalidArgumentError(
        "--tls_cert, --tls_key: give both or neither");
  }
  FOVEA_ASSIGN_OR_RETURN(std::string cert,
                         ReadPem(config.tls_cert, "--tls_cert"));
  FOVEA_ASSIGN_OR_RETURN(std::string key, ReadPem(config.tls_key, "--tls_key"));
  grpc::SslServerCredentialsOptions ssl(
      config.tls_client_ca.empty()
          ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
          : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  ssl.pem_key_cert_pairs.push_back({key, cert});
  if (!config.tls_client_ca.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::string ca,
                           ReadPem(config.tls_client_ca, "--tls_client_ca"));
    ssl.pem_root_certs = ca;
  }
  return grpc::SslServerCredentials(ssl);
}

// Every stage a Detect response can time: the server's own and core's.
std::vector<std::string> DetectStages() {
  std::vector<std::string> stages = {"queue", "decode", "encode"};
  for (std::string& stage : DetectStageNames()) {
    stages.push_back(std::move(stage));
  }
  return stages;
}

}  // namespace

int DefaultMaxMessageBytes(const FrameLimits& limits) {
  const int64_t raw = int64_t{limits.max_width} * limits.max_height * (3 + 4);
  return static_cast<int>(std::min<int64_t>(raw + (1 << 20), INT32_MAX));
}

ThreadBudget EffectiveThreads(const ServerConfig& config) {
  const int cores =
      config.cores > 0
          ? config.cores
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int workers = std::max(1, config.concurrency);
  const int wanted = config.threads_per_request > 0
                         ? config.threads_per_request
                         : std::max(1, cores / workers);
  ThreadBudget budget;
  budget.helpers =
      std::min(workers * (wanted - 1), std::max(0, cores - workers));
  budget.threads_per_request = 1 + std::min(wanted - 1, budget.helpers);
  return budget;
}

absl::Status Validate(const ServerConfig& config) {
  if (config.listen.empty()) {
    return absl::InvalidArgumentError("--listen: empty, expected host:port");
  }
  if (!config.record_dir.empty()) {
    RecorderConfig recorder;
    recorder.dir = config.record_dir;
    recorder.max_bytes = config.record_max_bytes;
    recorder.sample = config.record_sample;
    if (absl::Status s = Validate(recorder); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("--", s.message()));
    }
  }
  if (config.concurrency < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("--concurrency: ", config.concurrency, " is below 1"));
  }
  if (config.threads_per_request < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--threads_per_request: ", config.threads_per_request, " is negative"));
  }
  if (config.queue < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--queue: ", config.queue, " is negative"));
  }
  if (config.max_message_bytes < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--max_message_bytes: ", config.max_message_bytes, " is negative"));
  }
  if (config.memory_quota_bytes < (int64_t{16} << 20)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--memory_quota_mb: ", config.memory_quota_bytes >> 20,
                     " is below 16"));
  }
  if (!(config.max_connection_age_s >= 0.0) ||
      config.max_connection_age_s > kMaxConnectionAgeS) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max_connection_age_s: ", config.max_connection_age_s,
                     " is not in [0, ", kMaxConnectionAgeS, "]"));
  }
  if (!(config.max_connection_age_grace_s >= 0.0) ||
      config.max_connection_age_grace_s > kMaxConnectionAgeS) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--max_connection_age_grace_s: ", config.max_connection_age_grace_s,
        " is not in [0, ", kMaxConnectionAgeS, "]"));
  }
  if (!(config.stream_stall_timeout_s > 0.0) ||
      config.stream_stall_timeout_s > 3600.0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--stream_stall_timeout_s: ", config.stream_stall_timeout_s,
        " is not in (0, 3600]"));
  }
  if (config.max_track_streams < 1 || config.max_track_streams > 100000) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max_track_streams: ", config.max_track_streams,
                     " is not in [1, 100000]"));
  }
  if (config.max_track_streams_per_peer < 1 ||
      config.max_track_streams_per_peer > 100000) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--max_track_streams_per_peer: ", config.max_track_streams_per_peer,
        " is not in [1, 100000]"));
  }
  if (!(config.track_idle_timeout_s > 0.0) ||
      config.track_idle_timeout_s > 3600.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--track_idle_timeout_s: ", config.track_idle_timeout_s,
                     " is not in (0, 3600]"));
  }
  if (!(config.handshake_timeout_s > 0.0) ||
      config.handshake_timeout_s > 120.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--handshake_timeout_s: ", config.handshake_timeout_s,
                     " is not in (0, 120]"));
  }
  if (!(config.drain_delay_s >= 0.0) || config.drain_delay_s > 3600.0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--drain_delay_s: ", config.drain_delay_s, " is not in [0, 3600]"));
  }
  if (!(config.fd_high_water > 0.0) || config.fd_high_water > 1.0 ||
      !(config.fd_check_interval_s > 0.0)) {
    return absl::InvalidArgumentError(
        "fd_high_water must be in (0, 1] and fd_check_interval_s positive");
  }
  if (absl::Status status = Validate(config.limits); !status.ok()) {
    return absl::Status(
        status.code(),
        absl::StrCat("--max_width/--max_height: ", status.message()));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<FoveaServer>> FoveaServer::Start(
    ServerConfig config) {
  FOVEA_RETURN_IF_ERROR(Validate(config));
  if (config.max_message_bytes == 0) {
    config.max_message_bytes = DefaultMaxMessageBytes(config.limits);
  }
  InitMetrics(ServerVersion());
  InitStageSeries(DetectStages());
  SetAcceptReserve(config.fd_reserve);

  std::unique_ptr<FoveaServer> server(new FoveaServer);
  absl::StatusOr<LoadedModels> models = LoadModels(config.models_dir);
  if (!models.ok()) {
    return absl::Status(
        models.status().code(),
        absl::StrCat("--models_dir: ", models.status().message()));
  }
  server->models_ = std::make_unique<LoadedModels>(*std::move(models));
  if (!config.metrics_listen.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::unique_ptr<MetricsEndpoint> metrics,
                           MetricsEndpoint::Start(config.metrics_listen));
    server->metrics_ = std::move(metrics);
  }
  const ThreadBudget threads = EffectiveThreads(config);
  server->pool_ = std::make_unique<ThreadPool>(threads.helpers);
  server->work_ = std::make_unique<WorkQueue>(config.concurrency, config.queue,
                                              server->pool_.get(),
                                              threads.threads_per_request);
  ServiceConfig service;
  server->service_state_ = service.state;
  server->drain_delay_s_ = config.drain_delay_s;
  service.limits = config.limits;
  service.max_message_bytes = static_cast<uint64_t>(config.max_message_bytes);
  service.stream_stall_timeout = std::chrono::milliseconds(
      std::lround(config.stream_stall_timeout_s * 1000.0));
  service.before_detect_job = config.before_detect_job;
  service.at_stage_boundary = config.at_stage_boundary;
  service.on_stream_cancelled = config.on_stream_cancelled;
  service.segment_models = server->models_->View();
  service.model_versions = server->models_->versions;
  if (!config.record_dir.empty()) {
    RecorderConfig recorder;
    recorder.dir = config.record_dir;
    recorder.max_bytes = config.record_max_bytes;
    recorder.sample = config.record_sample;
    FOVEA_ASSIGN_OR_RETURN(server->recorder_, FlightRecorder::Start(recorder));
    service.recorder = server->recorder_.get();
  }
  StreamLimits stream_limits;
  stream_limits.max_streams = config.max_track_streams;
  stream_limits.max_streams_per_peer = config.max_track_streams_per_peer;
  stream_limits.idle_timeout = std::chrono::milliseconds(
      std::lround(config.track_idle_timeout_s * 1000.0));
  server->streams_ = std::make_unique<StreamRegistry>(stream_limits);
  service.streams = server->streams_.get();
  // Not limits: a stall watch is only ever opened for a call admitted.
  StreamLimits stall_limits;
  stall_limits.max_streams = std::numeric_limits<int>::max();
  stall_limits.max_streams_per_peer = std::numeric_limits<int>::max();
  stall_limits.idle_timeout = service.stream_stall_timeout;
  stall_limits.shed_reason = "stalled_stream";
  server->stalls_ = std::make_unique<StreamRegistry>(stall_limits);
  service.stalls = server->stalls_.get();
  server->service_ = std::make_unique<PerceptionService>(std::move(service),
                                                         server->work_.get());

  grpc::EnableDefaultHealthCheckService(true);
  // gRPC's own health service carries no protobuf descriptor; reflection
  // answers from the generated pool, so the contract's copy of
  // grpc.health.v1 (built into fovea_proto) is linked in and registered
  // here: grpcurl and `buf curl` can then call Health through reflection.
  (void)grpc::health::v1::HealthCheckRequest::descriptor();
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  // Refuse a port another process already serves (Linux would otherwise
  // share it silently with SO_REUSEPORT).
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  if (!config.reflection)
    builder.SetOption(std::make_unique<WithoutReflection>());
  builder.SetMaxReceiveMessageSize(config.max_message_bytes);
  builder.AddChannelArgument(
      GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS,
      static_cast<int>(std::lround(config.handshake_timeout_s * 1000.0)));
  grpc::ResourceQuota quota("fovea-server");
  quota.Resize(static_cast<size_t>(config.memory_quota_bytes));
  builder.SetResourceQuota(quota);
  if (config.max_connection_age_s > 0.0) {
    builder.AddChannelArgument(
        GRPC_ARG_MAX_CONNECTION_AGE_MS,
        static_cast<int>(std::lround(config.max_connection_age_s * 1000.0)));
    builder.AddChannelArgument(
        GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS,
        static_cast<int>(
            std::lround(config.max_connection_age_grace_s * 1000.0)));
  }
  FOVEA_ASSIGN_OR_RETURN(std::shared_ptr<grpc::ServerCredentials> credentials,
                         ServerCredentials(config));
  builder.AddListeningPort(config.listen, credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    return absl::UnavailableError(
        absl::StrCat("--listen: cannot listen on '", config.listen, "'"));
  }
  // The default health service starts with "" SERVING.
  server->SetServing(false);

  LogInfo(absl::StrFormat(
      "fovea-server %s listening on %s (port %d, %s), metrics %s, concurrency "
      "%d, threads per request %d (%d shared helpers), queue %d, max message "
      "%d bytes, memory quota %d MiB, max frame %dx%d",
      ServerVersion(), config.listen, server->port_,
      config.tls_cert.empty()        ? "plaintext"
      : config.tls_client_ca.empty() ? "TLS"
                                     : "mutual TLS",
      config.metrics_listen.empty()
          ? std::string("off")
          : absl::StrCat("on port ", server->metrics_port(), " /metrics"),
      config.concurrency, threads.threads_per_request, threads.helpers,
      config.queue, config.max_message_bytes,
      static_cast<int>(config.memory_quota_bytes >> 20),
      config.limits.max_width, config.limits.max_height));
  if (server->recorder_ != nullptr) {
    LogInfo(absl::StrFormat(
        "flight recorder: %.0f %% of the calls into %s, at most %d MiB (%d "
        "MiB held now)",
        100.0 * config.record_sample, config.record_dir,
        static_cast<int>(config.record_max_bytes >> 20),
        static_cast<int>(server->recorder_->bytes() >> 20)));
  }

  if (config.warm_up) {
    FoveaServer* self = server.get();
    server->warm_up_thread_ =
        std::thread([self, limits = config.limits,
                     before_warm_up = std::move(config.before_warm_up)] {
          self->WarmUp(limits, before_warm_up);
        });
  } else {
    MutexLock lock(&server->mu_);
    server->warmed_up_ = true;
    server->UpdateHealthLocked();
  }
  server->fd_thread_ =
      std::thread([self = server.get(), high = config.fd_high_water,
                   interval = config.fd_check_interval_s] {
        self->WatchDescriptors(high, interval);
      });
  return server;
}

FoveaServer::~FoveaServer() { Shutdown(absl::ZeroDuration()); }

int FoveaServer::metrics_port() const {
  return metrics_ == nullptr ? 0 : metrics_->port();
}

bool FoveaServer::warmed_up() const {
  MutexLock lock(&mu_);
  return warmed_up_;
}

bool FoveaServer::out_of_descriptors() const {
  MutexLock lock(&mu_);
  return out_of_descriptors_;
}

void FoveaServer::UpdateHealthLocked() {
  const bool serving = warmed_up_ && !draining_ && !out_of_descriptors_;
  if (serving == serving_) return;
  serving_ = serving;
  SetServing(serving);
  LogInfo(serving ? "health: SERVING" : "health: NOT_SERVING");
}

void FoveaServer::WatchDescriptors(double high_water, double interval_s) {
  MutexLock lock(&mu_);
  while (!shut_down_) {
    // Near the limit even /proc/self/fd cannot be opened: count that as
    // full.
    std::optional<DescriptorUse> use = CountDescriptors();
    if (!use.has_value()) use = DescriptorUse{1, 1};
    RecordDescriptors(use->open, use->limit, AcceptsRefused());
    if (use->limit > 0) {
      const double share = static_cast<double>(use->open) / use->limit;
      const bool out =
          out_of_descriptors_ ? share > 0.9 * high_water : share > high_water;
      if (out != out_of_descriptors_) {
        out_of_descriptors_ = out;
        if (out) {
          LogError(absl::StrFormat(
              "%d of %d file descriptors open: new connections cannot be "
              "accepted; health NOT_SERVING until they close",
              use->open, use->limit));
        } else {
          LogInfo(absl::StrFormat("%d of %d file descriptors open again",
                                  use->open, use->limit));
        }
        UpdateHealthLocked();
      }
    }
    mu_.AwaitWithTimeout(
        [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return shut_down_; },
        absl::Seconds(interval_s));
  }
}

void FoveaServer::SetServing(bool serving) {
  grpc::HealthCheckServiceInterface* health =
      server_ == nullptr ? nullptr : server_->GetHealthCheckService();
  if (health == nullptr) return;
  for (const char* name : kHealthNames) {
    health->SetServingStatus(name, serving);
  }
}

void FoveaServer::WarmUp(const FrameLimits& limits,
                         const std::function<void()>& before_warm_up) {
  if (before_warm_up) before_warm_up();
  const Clock::time_point start = Clock::now();
  const v1::DetectRequest request = WarmUpRequest();
  absl::StatusOr<DetectOptions> options = ToDetectOptions(request.options());
  absl::StatusOr<v1::DetectResponse> response =
      options.ok() ? HandleDetect(request, *options, limits, {}, 0.0)
                   : absl::StatusOr<v1::DetectResponse>(options.status());
  const double ms = SecondsSince(start) * 1e3;
  if (response.ok()) {
    LogInfo(absl::StrFormat("warm-up Detect done in %.1f ms, %d points", ms,
                            response->points_size()));
  } else {
    LogError(absl::StrCat(
        "warm-up Detect failed after ", absl::StrFormat("%.1f", ms),
        " ms (serving anyway): ", response.status().ToString()));
  }
  MutexLock lock(&mu_);
  warmed_up_ = true;
  UpdateHealthLocked();
}

void FoveaServer::Drain() {
  MutexLock lock(&mu_);
  if (draining_) return;
  draining_ = true;
  LogInfo("draining");
  UpdateHealthLocked();
}

void FoveaServer::Shutdown(absl::Duration grace) {
  {
    MutexLock lock(&mu_);
    if (shut_down_) return;
    shut_down_ = true;
  }
  Drain();
  if (server_ != nullptr) {
    if (drain_delay_s_ > 0.0) {
      LogInfo(
          absl::StrFormat("serving %.1f s more while health says "
                          "NOT_SERVING",
                          drain_delay_s_));
      absl::SleepFor(absl::Seconds(drain_delay_s_));
    }
    LogInfo(
        absl::StrCat("shutting down: new calls refused, in-flight calls "
                     "have ",
                     absl::FormatDuration(grace)));
    const Clock::time_point start = Clock::now();
    service_state_->refusing.store(true);
    const absl::Time deadline = absl::Now() + grace;
    while (service_state_->calls.load() > 0 && absl::Now() < deadline) {
      absl::SleepFor(absl::Milliseconds(5));
    }
    // What is left: health Watch streams (which never end on their own),
    // calls past the grace.
    server_->Shutdown(absl::ToChronoTime(absl::Now()));
    // Every call's OnDone has run, and with it its CallRecord's last touch
    // of the state (~CallRecord).
    TsanHappensAfter(service_state_.get());
    LogInfo(absl::StrFormat("gRPC server stopped after %.1f ms",
                            SecondsSince(start) * 1e3));
  }
  if (work_ != nullptr) work_->Stop();
  if (warm_up_thread_.joinable()) warm_up_thread_.join();
  if (fd_thread_.joinable()) fd_thread_.join();
  metrics_.reset();
}

}  // namespace fovea::server
