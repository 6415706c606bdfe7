#ifndef FOVEA_SERVER_METRICS_H_
#define FOVEA_SERVER_METRICS_H_

#include <google/protobuf/descriptor.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea::server {

// The server's Prometheus metrics, behind functions: prometheus-cpp types
// never leave metrics.cc. One process-wide registry.
//
// gRPC series use the names and labels of go-grpc-prometheus, so the
// gRPC ecosystem's dashboards work unchanged. Each carries grpc_type
// ("unary" or "server_stream"), grpc_service ("fovea.v1.Perception") and
// grpc_method ("Detect", "Segment", "SegmentIncremental",
// "GetCapabilities"):
//   grpc_server_started_total          counter
//   grpc_server_handled_total          counter, plus grpc_code ("OK",
//                                      "InvalidArgument", ...: gRPC-Go's
//                                      spelling, see GrpcCodeName)
//   grpc_server_msg_received_total     counter
//   grpc_server_msg_sent_total         counter
//   grpc_server_handling_seconds       histogram, buckets .005 .01 .025 .05
//                                      .1 .25 .5 1 2.5 5 10 (Prometheus'
//                                      DefBuckets, as go-grpc-prometheus)
// Fovea's own:
//   fovea_stage_duration_seconds{stage}  histogram; stages are core's
//                                        timings plus "queue", "decode",
//                                        "encode"
//   fovea_time_to_first_object_seconds{grpc_method}  histogram (gRPC
//                                        buckets): call start to the first
//                                        object message of Segment /
//                                        SegmentIncremental
//   fovea_objects_per_request{grpc_method}  histogram: objects sent by one
//                                        segmentation call
//   fovea_segment_stops_total{grpc_method, reason}  counter: why each
//                                        segmentation call stopped (done,
//                                        max_objects, time_budget, deadline,
//                                        cancelled, error)
//   fovea_calls_shed_total{reason}       counter: calls the server ended
//                                        itself (abandoned_in_queue,
//                                        stalled_stream, idle_stream,
//                                        stream_limit, busy)
//   fovea_track_open_streams               gauge: Track streams open
//   fovea_track_frames_total{outcome}      counter: segmented, reused,
//                                        skipped
//   fovea_track_frame_seconds              histogram: a frame's arrival to
//                                        its response
//   fovea_open_file_descriptors, fovea_file_descriptor_limit  gauges
//   fovea_connections_refused_total      counter: closed by the accept guard
//   fovea_inflight_requests              gauge: calls started, not finished
//   fovea_queue_wait_seconds             histogram: submit to start of work
//   fovea_build_info{version}            gauge, always 1
// Every series of every method exists at zero from InitMetrics on (every
// method x every code for handled_total).

// The gRPC service the gRPC series describe.
inline constexpr std::string_view kServiceName = "fovea.v1.Perception";
// kServiceName's descriptor (the generated pool's): its methods, in the
// contract's order, are the one list the metrics and the service's
// handlers (by index) take them from.
const google::protobuf::ServiceDescriptor& PerceptionDescriptor();

// Sets fovea_build_info{version} to 1. Call once at start-up; later calls
// are ignored. Every other family and series exists at zero from the first
// call of any function here (this one included).
void InitMetrics(std::string_view version);

// Creates fovea_stage_duration_seconds{stage} at zero for each name.
void InitStageSeries(const std::vector<std::string>& stages);

// Per call. `method` is one of the four Perception methods (anything else
// is a bug: FOVEA_CHECK).
void RecordCallStarted(std::string_view method);
void RecordMessageReceived(std::string_view method);
void RecordMessageSent(std::string_view method);
void RecordCallHandled(std::string_view method, absl::StatusCode code,
                       double seconds);

void RecordStage(std::string_view stage, double seconds);
void RecordQueueWait(double seconds);
// Segmentation calls ("Segment", "SegmentIncremental").
void RecordFirstObject(std::string_view method, double seconds);
void RecordObjectsPerRequest(std::string_view method, int objects);
// Why a segmentation call stopped: "done", "max_objects", "time_budget",
// "deadline", "cancelled" or "error".
void RecordStopReason(std::string_view method, std::string_view reason);
// fovea_calls_shed_total{reason}: a call abandoned while it waited for a
// worker; a stream cancelled because its client stopped reading.
void RecordAbandonedInQueue();
void RecordStalledStream();
// fovea_calls_shed_total{reason}: idle_stream (a Track stream that sent
// nothing for its idle timeout), stream_limit (a Track stream refused by the
// open-stream limits), busy (a call refused because the work queue was
// full).
void RecordShed(std::string_view reason);
// Track: fovea_track_open_streams (gauge), fovea_track_frames_total{outcome}
// (segmented, reused, skipped) and fovea_track_frame_seconds (arrival to
// response, for the frames processed).
void AddTrackStreams(int delta);
void RecordTrackFrame(std::string_view outcome, double seconds);
void IncrementInflight();
void DecrementInflight();
// fovea_open_file_descriptors, fovea_file_descriptor_limit (gauges) and
// fovea_connections_refused_total (counter, set to `refused_total`:
// connections the accept guard closed or delayed).
void RecordDescriptors(int open, int limit, int64_t refused_total);
// The flight recorder (flight_recorder.h): fovea_recorder_records_total
// {outcome} (written, written_without_frame, queue_full, too_large, error)
// and fovea_recorder_bytes, the size of what it holds on disk.
void RecordRecorderOutcome(std::string_view outcome);
void SetRecorderBytes(int64_t bytes);

// The HTTP endpoint serving /metrics. Stops serving when destroyed.
class MetricsEndpoint {
 public:
  // Listens on `listen` ("host:port"; port 0 picks a free one).
  // UNAVAILABLE when the address cannot be bound.
  static absl::StatusOr<std::unique_ptr<MetricsEndpoint>> Start(
      const std::string& listen);
  ~MetricsEndpoint();

  // The bound port.
  int port() const;

 private:
  struct Impl;
  explicit MetricsEndpoint(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fovea::server

#endif  // FOVEA_SERVER_METRICS_H_
