#ifndef FOVEA_SERVER_SERVER_H_
#define FOVEA_SERVER_SERVER_H_

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/base/mutex.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/models.h"
#include "server/flight_recorder.h"
#include "server/metrics.h"
#include "server/perception_service.h"
#include "server/stream_registry.h"
#include "server/work_queue.h"

namespace fovea::server {

// The largest request worth receiving with these frame limits: a raw
// frame of the largest size with packed rows (rgb8, 3 bytes a pixel, and
// 32FC1 depth, 4) and 1 MiB for the options and the rest: 15.5 MiB at
// 1920x1080. A compressed frame of that size is smaller.
int DefaultMaxMessageBytes(const FrameLimits& limits);

// Memory gRPC may use for what it receives and buffers (the resource
// quota), default: requests larger than fit are refused with
// RESOURCE_EXHAUSTED instead of growing the process.
inline constexpr int64_t kDefaultMemoryQuotaBytes = int64_t{512} << 20;

struct ServerConfig {
  std::string listen = "127.0.0.1:50051";  // host:port of the gRPC server
  std::string metrics_listen;              // host:port of /metrics; empty: none
  int concurrency = 1;                     // frames computed at once, >= 1
  int queue = 2;                           // frames waiting for a worker, >= 0
  // Threads one frame may use (ParallelScope), >= 0; 0: cores /
  // concurrency. However many are asked for, the helpers shared by all
  // workers are at most cores - concurrency, so that the threads computing
  // at once never outnumber the cores (EffectiveThreadsPerRequest).
  int threads_per_request = 0;
  int cores = 0;  // 0: std::thread::hardware_concurrency()
  // Largest request, > 0; 0: DefaultMaxMessageBytes(limits).
  int max_message_bytes = 0;
  // gRPC's resource quota, bytes (>= 16 MiB).
  int64_t memory_quota_bytes = kDefaultMemoryQuotaBytes;
  FrameLimits limits;   // largest frame
  bool warm_up = true;  // run one Detect before reporting SERVING
  // gRPC server reflection (grpcurl, grpc_cli list the services).
  bool reflection = true;
  // TLS: PEM files (paths). With a certificate and key the gRPC port
  // speaks TLS only; with a client CA too, every client must present a
  // certificate that CA signed (mutual TLS). Empty: plaintext.
  std::string tls_cert;
  std::string tls_key;
  std::string tls_client_ca;
  // Seconds after which the server asks a client connection to go away
  // (GOAWAY; gRPC adds +-10 % jitter), so that clients re-resolve DNS and
  // spread over replicas added since they connected; calls in flight get
  // max_connection_age_grace_s more to finish. 0: connections live forever.
  double max_connection_age_s = 0.0;
  // >= 0; a day: a Track stream, a robot's session, is not cut.
  double max_connection_age_grace_s = 86400.0;
  // A stream whose client takes no message for this long while results
  // wait for it is cancelled (ServiceConfig::stream_stall_timeout), (0,
  // 3600].
  double stream_stall_timeout_s = 5.0;
  // Track streams: open at once in all and from one peer address, [1,
  // 100000]; one whose client sent nothing for track_idle_timeout_s, with
  // none of its frames waiting or running, is closed, (0, 3600].
  int max_track_streams = 64;
  int max_track_streams_per_peer = 8;
  double track_idle_timeout_s = 10.0;
  // A connection that has not completed the HTTP/2 handshake (preface and
  // settings) within this many seconds is closed: silent connections
  // cannot pile up to the descriptor limit. (0, 120].
  double handshake_timeout_s = 5.0;
  // Health turns NOT_SERVING while the process holds more than this share
  // of its descriptor limit (the listener could not accept), and SERVING
  // again below 0.9 of it. Checked every fd_check_interval_s. (0, 1].
  // On Shutdown, seconds health says NOT_SERVING while calls are still
  // served, so load balancers move traffic away before calls are refused.
  double drain_delay_s = 0.0;
  double fd_high_water = 0.95;
  double fd_check_interval_s = 1.0;
  // New connections are closed at once while fewer than this many
  // descriptors are left under the limit (accept_guard.h); 0: off.
  int fd_reserve = 64;
  // Folder of the trained models (LoadModels); start-up fails when a model
  // is missing or corrupt.
  std::string models_dir = FOVEA_DEFAULT_MODELS_DIR;
  // The flight recorder (flight_recorder.h): record_dir empty is off;
  // otherwise record_sample of the calls (0, 1] are kept there, within
  // record_max_bytes.
  std::string record_dir;
  int64_t record_max_bytes = int64_t{1} << 30;
  double record_sample = 1.0;
  // Test hooks, null in production: see ServiceConfig::before_detect_job,
  // ServiceConfig::at_stage_boundary and ServiceConfig::on_stream_cancelled.
  std::function<void()> before_detect_job;
  std::function<void()> at_stage_boundary;
  std::function<void()> on_stream_cancelled;
  // Test hook, null in production: called on the warm-up thread before the
  // warm-up Detect; tests block it to observe health before warm-up ends.
  std::function<void()> before_warm_up;
};

// The threads a frame gets with `config`, and the pool's helpers (shared
// by all workers): threads_per_request (or cores / concurrency when 0),
// cut so that concurrency + helpers <= max(cores, concurrency).
struct ThreadBudget {
  int threads_per_request = 1;
  int helpers = 0;
};
ThreadBudget EffectiveThreads(const ServerConfig& config);

// Names the flag of the first bad field (--concurrency, ...).
absl::Status Validate(const ServerConfig& config);

// The running server: the Perception service, the grpc.health.v1 service
// (for "" and "fovea.v1.Perception"), server reflection, the worker pool
// and the /metrics endpoint.
//
// Metrics: every fovea_stage_duration_seconds series a Detect can report
// (core's DetectStageNames plus "queue", "decode", "encode") exists at zero
// from Start on, warm-up or not.
//
// Health: NOT_SERVING from start until the warm-up (one Detect on a small
// synthetic frame, on its own thread) is done, then SERVING; NOT_SERVING
// again from Drain on. A warm-up that fails is logged as an error and the
// server still reports SERVING: the failure is then the scene's or core's,
// and each call reports its own error.
class FoveaServer {
 public:
  // Validates `config`, loads the models, starts listening and returns at
  // once (the warm-up runs in the background). UNAVAILABLE when an address
  // cannot be bound; LoadModels' errors (NOT_FOUND, INVALID_ARGUMENT)
  // prefixed with "--models_dir".
  static absl::StatusOr<std::unique_ptr<FoveaServer>> Start(
      ServerConfig config);

  // Shutdown(absl::ZeroDuration()) unless already shut down.
  ~FoveaServer();

  FoveaServer(const FoveaServer&) = delete;
  FoveaServer& operator=(const FoveaServer&) = delete;

  int port() const { return port_; }
  // The flight recorder; null when --record_dir is empty.
  FlightRecorder* recorder() const { return recorder_.get(); }
  // 0 without a metrics endpoint.
  int metrics_port() const;

  // True once the warm-up finished (OK or not).
  bool warmed_up() const;

  // True while the process holds more descriptors than fd_high_water of
  // its limit (health says NOT_SERVING meanwhile).
  bool out_of_descriptors() const;

  // Health NOT_SERVING for both names; calls are still served, so load
  // balancers can move traffic away first. Idempotent.
  void Drain();

  // Drain; keep serving for drain_delay_s; then refuse new calls
  // (UNAVAILABLE), let in-flight calls (queued ones too) finish for up to
  // `grace`, and stop the gRPC server at once: what is left (health Watch
  // streams, calls past the grace) is cancelled (their jobs see CANCELLED
  // at their next stage boundary) and waited for; stop the workers and the
  // metrics endpoint. Idempotent; blocks until done.
  void Shutdown(absl::Duration grace);

  // Detect jobs accepted and waiting for a worker.
  int queued_jobs() const { return work_->waiting(); }
  // Jobs on a worker now (a call's answer may reach its client a moment
  // before its job leaves the worker).
  int running_jobs() const { return work_->running(); }

 private:
  FoveaServer() = default;
  void SetServing(bool serving);
  // What health should say now: warmed up, not draining, descriptors left.
  void UpdateHealthLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Every fd_check_interval_s until shutdown: open descriptors against the
  // limit.
  void WatchDescriptors(double high_water, double interval_s);
  void WarmUp(const FrameLimits& limits,
              const std::function<void()>& before_warm_up);

  int port_ = 0;
  std::unique_ptr<LoadedModels> models_;  // the service points into it
  std::unique_ptr<ThreadPool> pool_;      // the workers' helpers
  std::unique_ptr<WorkQueue> work_;
  // Before service_: the calls hand themselves to it until the last ends.
  std::unique_ptr<FlightRecorder> recorder_;
  std::unique_ptr<StreamRegistry> streams_;  // the Track streams
  // Segment streams whose last messages wait for their client.
  std::unique_ptr<StreamRegistry> stalls_;
  std::shared_ptr<ServiceState> service_state_;
  double drain_delay_s_ = 0.0;
  std::unique_ptr<PerceptionService> service_;
  std::unique_ptr<MetricsEndpoint> metrics_;
  std::unique_ptr<grpc::Server> server_;  // after service_: destroyed first
  std::thread warm_up_thread_;
  std::thread fd_thread_;

  mutable Mutex mu_;
  bool warmed_up_ ABSL_GUARDED_BY(mu_) = false;
  bool draining_ ABSL_GUARDED_BY(mu_) = false;
  bool shut_down_ ABSL_GUARDED_BY(mu_) = false;
  bool out_of_descriptors_ ABSL_GUARDED_BY(mu_) = false;
  bool serving_ ABSL_GUARDED_BY(mu_) = false;  // what health says
};

}  // namespace fovea::server

#endif  // FOVEA_SERVER_SERVER_H_
