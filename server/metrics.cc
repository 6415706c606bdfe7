#include "server/metrics.h"

#include <google/protobuf/descriptor.h>
#include <prometheus/counter.h>
#include <prometheus/exposer.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include <array>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "fovea/v1/perception.pb.h"
#include "server/status_util.h"

namespace fovea::server {
namespace {

struct MethodInfo {
  std::string name;
  std::string type;  // go-grpc-prometheus' grpc_type
};

}  // namespace

const google::protobuf::ServiceDescriptor& PerceptionDescriptor() {
  // Through a message of perception.proto, so that every program linking
  // the metrics links (and registers) the file that declares the service.
  static const google::protobuf::ServiceDescriptor* const service =
      v1::GetCapabilitiesRequest::descriptor()
          ->file()
          ->pool()
          ->FindServiceByName(std::string(kServiceName));
  FOVEA_CHECK(service != nullptr);
  return *service;
}

namespace {

// The methods of kServiceName as its descriptor lists them, in its order:
// the one list of methods the metrics know.
const std::vector<MethodInfo>& Methods() {
  static const auto* const methods = [] {
    auto* out = new std::vector<MethodInfo>;
    const google::protobuf::ServiceDescriptor& service = PerceptionDescriptor();
    for (int i = 0; i < service.method_count(); ++i) {
      const google::protobuf::MethodDescriptor* m = service.method(i);
      const bool in = m->client_streaming(), out_stream = m->server_streaming();
      out->push_back({m->name(), in && out_stream ? "bidi_stream"
                                 : in             ? "client_stream"
                                 : out_stream     ? "server_stream"
                                                  : "unary"});
    }
    return out;
  }();
  return *methods;
}

// go-grpc-prometheus' handling-time buckets (Prometheus' DefBuckets).
const prometheus::Histogram::BucketBoundaries& HandlingBuckets() {
  static const auto* buckets = new prometheus::Histogram::BucketBoundaries{
      0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10};
  return *buckets;
}

// Stages and queue waits are shorter than whole calls: finer at the low
// end (0.5 ms up), same top.
const prometheus::Histogram::BucketBoundaries& StageBuckets() {
  static const auto* buckets = new prometheus::Histogram::BucketBoundaries{
      0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
      0.1,    0.25,  0.5,    1,     2.5,  5,     10};
  return *buckets;
}

// The series of one method, created up front; updates take no registry
// lock.
struct MethodSeries {
  prometheus::Counter* started = nullptr;
  prometheus::Counter* received = nullptr;
  prometheus::Counter* sent = nullptr;
  prometheus::Histogram* handling = nullptr;
  std::array<prometheus::Counter*, kAllStatusCodes.size()> handled{};
};

class Metrics {
 public:
  static Metrics& Get() {
    static Metrics* metrics = new Metrics;
    return *metrics;
  }

  const std::shared_ptr<prometheus::Registry>& registry() const {
    return registry_;
  }

  MethodSeries& Method(std::string_view method) {
    const std::vector<MethodInfo>& methods = Methods();
    for (size_t i = 0; i < methods.size(); ++i) {
      if (methods[i].name == method) return methods_[i];
    }
    std::fprintf(stderr, "metrics: unknown method '%.*s'\n",
                 static_cast<int>(method.size()), method.data());
    FOVEA_CHECK(false);
    return methods_[0];
  }

  prometheus::Histogram& Stage(std::string_view stage) {
    return stage_family_.Add({{"stage", std::string(stage)}}, StageBuckets());
  }

  prometheus::Histogram& FirstObject(std::string_view method) {
    return first_object_family_.Add({{"grpc_method", std::string(method)}},
                                    HandlingBuckets());
  }
  prometheus::Histogram& Objects(std::string_view method) {
    static const auto* buckets = new prometheus::Histogram::BucketBoundaries{
        0, 1, 2, 3, 5, 8, 13, 21, 34, 55, 100};
    return objects_family_.Add({{"grpc_method", std::string(method)}},
                               *buckets);
  }

  prometheus::Counter& Stops(std::string_view method, std::string_view reason) {
    return stops_family_.Add({{"grpc_method", std::string(method)},
                              {"reason", std::string(reason)}});
  }

  prometheus::Counter& TrackFrames(std::string_view outcome) {
    return track_frames_family_.Add({{"outcome", std::string(outcome)}});
  }
  prometheus::Gauge& track_streams() { return track_streams_; }
  prometheus::Histogram& track_frame_seconds() { return track_frame_seconds_; }

  prometheus::Counter& Shed(std::string_view reason) {
    return shed_family_.Add({{"reason", std::string(reason)}});
  }

  prometheus::Counter& Recorded(std::string_view outcome) {
    return recorder_family_.Add({{"outcome", std::string(outcome)}});
  }
  prometheus::Gauge& recorder_bytes() { return recorder_bytes_; }

  prometheus::Gauge& inflight() { return inflight_; }
  prometheus::Gauge& open_fds() { return open_fds_; }
  prometheus::Gauge& fd_limit() { return fd_limit_; }
  prometheus::Counter& refused() { return refused_; }
  prometheus::Histogram& queue_wait() { return queue_wait_; }

  void SetBuildInfo(std::string_view version) {
    build_info_family_.Add({{"version", std::string(version)}}).Set(1);
  }

 private:
  Metrics()
      : registry_(std::make_shared<prometheus::Registry>()),
        started_family_(prometheus::BuildCounter()
                            .Name("grpc_server_started_total")
                            .Help("Total number of RPCs started on the server.")
                            .Register(*registry_)),
        handled_family_(
            prometheus::BuildCounter()
                .Name("grpc_server_handled_total")
                .Help("Total number of RPCs completed on the server, "
                      "regardless of success or failure.")
                .Register(*registry_)),
        received_family_(
            prometheus::BuildCounter()
                .Name("grpc_server_msg_received_total")
                .Help("Total number of RPC stream messages received on the "
                      "server.")
                .Register(*registry_)),
        sent_family_(prometheus::BuildCounter()
                         .Name("grpc_server_msg_sent_total")
                         .Help("Total number of gRPC stream messages sent by "
                               "the server.")
                         .Register(*registry_)),
        handling_family_(
            prometheus::BuildHistogram()
                .Name("grpc_server_handling_seconds")
                .Help("Histogram of response latency (seconds) of gRPC that "
                      "had been application-level handled by the server.")
                .Register(*registry_)),
        stage_family_(
            prometheus::BuildHistogram()
                .Name("fovea_stage_duration_seconds")
                .Help("Wall time of one pipeline stage of one call, seconds.")
                .Register(*registry_)),
        first_object_family_(
            prometheus::BuildHistogram()
                .Name("fovea_time_to_first_object_seconds")
                .Help("From the start of a segmentation call to its first "
                      "object message, seconds.")
                .Register(*registry_)),
        objects_family_(prometheus::BuildHistogram()
                            .Name("fovea_objects_per_request")
                            .Help("Objects sent by one segmentation call.")
                            .Register(*registry_)),
        stops_family_(prometheus::BuildCounter()
                          .Name("fovea_segment_stops_total")
                          .Help("Segmentation calls by the reason they "
                                "stopped.")
                          .Register(*registry_)),
        shed_family_(prometheus::BuildCounter()
                         .Name("fovea_calls_shed_total")
                         .Help("Calls the server ended on its own to protect "
                               "the others: abandoned_in_queue (the client "
                               "left or its deadline passed before a worker "
                               "took the call), stalled_stream (the client "
                               "stopped reading a stream).")
                         .Register(*registry_)),
        track_frames_family_(
            prometheus::BuildCounter()
                .Name("fovea_track_frames_total")
                .Help("Frames of Track streams by outcome: segmented, region "
                      "(only the part that changed segmented, the rest kept), "
                      "refined "
                      "(a still scene's mean of frames segmented), reused (the "
                      "scene had not changed), skipped (a newer frame "
                      "replaced it before it was processed, or the server was "
                      "busy).")
                .Register(*registry_)),
        track_streams_(prometheus::BuildGauge()
                           .Name("fovea_track_open_streams")
                           .Help("Track streams open now.")
                           .Register(*registry_)
                           .Add({})),
        track_frame_seconds_(
            prometheus::BuildHistogram()
                .Name("fovea_track_frame_seconds")
                .Help("From a Track frame's arrival to its response, "
                      "seconds.")
                .Register(*registry_)
                .Add({}, StageBuckets())),
        open_fds_(prometheus::BuildGauge()
                      .Name("fovea_open_file_descriptors")
                      .Help("File descriptors the process holds.")
                      .Register(*registry_)
                      .Add({})),
        fd_limit_(prometheus::BuildGauge()
                      .Name("fovea_file_descriptor_limit")
                      .Help("The soft RLIMIT_NOFILE.")
                      .Register(*registry_)
                      .Add({})),
        refused_(prometheus::BuildCounter()
                     .Name("fovea_connections_refused_total")
                     .Help("Connections closed at once (or delayed) because "
                           "too few file descriptors were left.")
                     .Register(*registry_)
                     .Add({})),
        inflight_(prometheus::BuildGauge()
                      .Name("fovea_inflight_requests")
                      .Help("Calls started and not yet finished, queued "
                            "ones included.")
                      .Register(*registry_)
                      .Add({})),
        queue_wait_(prometheus::BuildHistogram()
                        .Name("fovea_queue_wait_seconds")
                        .Help("Time a Detect job waited for a worker, seconds.")
                        .Register(*registry_)
                        .Add({}, StageBuckets())),
        recorder_family_(prometheus::BuildCounter()
                             .Name("fovea_recorder_records_total")
                             .Help("Calls the flight recorder handled, by "
                                   "outcome: written, written_without_frame, "
                                   "queue_full (dropped: the writer was "
                                   "behind), too_large, error.")
                             .Register(*registry_)),
        recorder_bytes_(prometheus::BuildGauge()
                            .Name("fovea_recorder_bytes")
                            .Help("Bytes the flight recorder's files take "
                                  "(at most --record_max_mb).")
                            .Register(*registry_)
                            .Add({})),
        build_info_family_(prometheus::BuildGauge()
                               .Name("fovea_build_info")
                               .Help("Always 1; the label is the server "
                                     "version.")
                               .Register(*registry_)) {
    const std::vector<MethodInfo>& methods = Methods();
    methods_.resize(methods.size());
    for (size_t i = 0; i < methods.size(); ++i) {
      const prometheus::Labels labels = {
          {"grpc_type", methods[i].type},
          {"grpc_service", std::string(kServiceName)},
          {"grpc_method", methods[i].name}};
      MethodSeries& series = methods_[i];
      series.started = &started_family_.Add(labels);
      series.received = &received_family_.Add(labels);
      series.sent = &sent_family_.Add(labels);
      series.handling = &handling_family_.Add(labels, HandlingBuckets());
      if (methods[i].type == "server_stream") {
        FirstObject(methods[i].name);
        Objects(methods[i].name);
        for (const char* reason : {"done", "max_objects", "time_budget",
                                   "deadline", "cancelled", "error"}) {
          Stops(methods[i].name, reason);
        }
      }
      for (const char* reason : {"abandoned_in_queue", "stalled_stream",
                                 "idle_stream", "stream_limit", "busy"}) {
        Shed(reason);
      }
      for (const char* outcome :
           {"segmented", "region", "refined", "reused", "skipped"}) {
        TrackFrames(outcome);
      }
      for (size_t c = 0; c < kAllStatusCodes.size(); ++c) {
        prometheus::Labels with_code = labels;
        with_code["grpc_code"] = std::string(GrpcCodeName(kAllStatusCodes[c]));
        series.handled[c] = &handled_family_.Add(with_code);
      }
    }
  }

  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>& started_family_;
  prometheus::Family<prometheus::Counter>& handled_family_;
  prometheus::Family<prometheus::Counter>& received_family_;
  prometheus::Family<prometheus::Counter>& sent_family_;
  prometheus::Family<prometheus::Histogram>& handling_family_;
  prometheus::Family<prometheus::Histogram>& stage_family_;
  prometheus::Family<prometheus::Histogram>& first_object_family_;
  prometheus::Family<prometheus::Histogram>& objects_family_;
  prometheus::Family<prometheus::Counter>& stops_family_;
  prometheus::Family<prometheus::Counter>& shed_family_;
  prometheus::Family<prometheus::Counter>& track_frames_family_;
  prometheus::Gauge& track_streams_;
  prometheus::Histogram& track_frame_seconds_;
  prometheus::Gauge& open_fds_;
  prometheus::Gauge& fd_limit_;
  prometheus::Counter& refused_;
  prometheus::Gauge& inflight_;
  prometheus::Histogram& queue_wait_;
  prometheus::Family<prometheus::Counter>& recorder_family_;
  prometheus::Gauge& recorder_bytes_;
  prometheus::Family<prometheus::Gauge>& build_info_family_;
  std::vector<MethodSeries> methods_;  // per Methods() entry
};

size_t CodeIndex(absl::StatusCode code) {
  const int value = static_cast<int>(code);
  if (value < 0 || value >= static_cast<int>(kAllStatusCodes.size())) {
    return static_cast<size_t>(absl::StatusCode::kUnknown);
  }
  return static_cast<size_t>(value);
}

}  // namespace

void InitMetrics(std::string_view version) {
  static std::once_flag once;
  std::call_once(once, [version] { Metrics::Get().SetBuildInfo(version); });
}

void InitStageSeries(const std::vector<std::string>& stages) {
  for (const std::string& stage : stages) Metrics::Get().Stage(stage);
}

void RecordCallStarted(std::string_view method) {
  Metrics::Get().Method(method).started->Increment();
}

void RecordMessageReceived(std::string_view method) {
  Metrics::Get().Method(method).received->Increment();
}

void RecordMessageSent(std::string_view method) {
  Metrics::Get().Method(method).sent->Increment();
}

void RecordCallHandled(std::string_view method, absl::StatusCode code,
                       double seconds) {
  MethodSeries& series = Metrics::Get().Method(method);
  series.handled[CodeIndex(code)]->Increment();
  series.handling->Observe(seconds);
}

void RecordStage(std::string_view stage, double seconds) {
  Metrics::Get().Stage(stage).Observe(seconds);
}

void RecordQueueWait(double seconds) {
  Metrics::Get().queue_wait().Observe(seconds);
}

void RecordFirstObject(std::string_view method, double seconds) {
  Metrics::Get().FirstObject(method).Observe(seconds);
}

void RecordObjectsPerRequest(std::string_view method, int objects) {
  Metrics::Get().Objects(method).Observe(objects);
}

void RecordStopReason(std::string_view method, std::string_view reason) {
  Metrics::Get().Stops(method, reason).Increment();
}

void RecordAbandonedInQueue() {
  Metrics::Get().Shed("abandoned_in_queue").Increment();
}

void RecordStalledStream() {
  Metrics::Get().Shed("stalled_stream").Increment();
}

void RecordShed(std::string_view reason) {
  Metrics::Get().Shed(reason).Increment();
}

void AddTrackStreams(int delta) {
  Metrics::Get().track_streams().Increment(delta);
}

void RecordTrackFrame(std::string_view outcome, double seconds) {
  Metrics& metrics = Metrics::Get();
  metrics.TrackFrames(outcome).Increment();
  if (outcome != "skipped") metrics.track_frame_seconds().Observe(seconds);
}

void RecordDescriptors(int open, int limit, int64_t refused_total) {
  Metrics& metrics = Metrics::Get();
  metrics.open_fds().Set(open);
  metrics.fd_limit().Set(limit);
  const double delta =
      static_cast<double>(refused_total) - metrics.refused().Value();
  if (delta > 0) metrics.refused().Increment(delta);
}

void RecordRecorderOutcome(std::string_view outcome) {
  Metrics::Get().Recorded(outcome).Increment();
}

void SetRecorderBytes(int64_t bytes) {
  Metrics::Get().recorder_bytes().Set(static_cast<double>(bytes));
}

void IncrementInflight() { Metrics::Get().inflight().Increment(); }

void DecrementInflight() { Metrics::Get().inflight().Decrement(); }

// Handler threads of /metrics.
constexpr int kMetricsThreads = 16;

struct MetricsEndpoint::Impl {
  std::unique_ptr<prometheus::Exposer> exposer;
};

MetricsEndpoint::MetricsEndpoint(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}

MetricsEndpoint::~MetricsEndpoint() = default;

absl::StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Start(
    const std::string& listen) {
  auto impl = std::make_unique<Impl>();
  try {
    // civetweb's options: enough handler threads that a few slow clients
    // cannot take them all, and a request that has not arrived whole
    // within 2 s is dropped (slowloris); a scrape takes milliseconds.
    impl->exposer =
        std::make_unique<prometheus::Exposer>(std::vector<std::string>{
            "listening_ports", listen, "num_threads",
            std::to_string(kMetricsThreads), "request_timeout_ms", "2000"});
  } catch (const std::exception& e) {
    return absl::UnavailableError(absl::StrCat(
        "--metrics_listen: cannot listen on '", listen, "': ", e.what()));
  }
  impl->exposer->RegisterCollectable(Metrics::Get().registry());
  return std::unique_ptr<MetricsEndpoint>(new MetricsEndpoint(std::move(impl)));
}

int MetricsEndpoint::port() const {
  const std::vector<int> ports = impl_->exposer->GetListeningPorts();
  return ports.empty() ? 0 : ports.front();
}

}  // namespace fovea::server
