#ifndef FOVEA_CLIENT_FOVEA_CLIENT_H_
#define FOVEA_CLIENT_FOVEA_CLIENT_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/channel.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/channel.h"

// A small synchronous client for fovea.v1.Perception and grpc.health.v1,
// to one server or several replicas (client/channel.h: ClientOptions, the
// targets Connect takes, how calls are spread and retried). The pieces to
// build requests live beside it: client/frame_builder.h (frames from raw
// buffers or PNG/JPEG bytes), client/option_names.h (enum names as typed
// on a command line), client/rle.h (object masks).

namespace fovea::client {

// Gets a fovea.v1.SegmentResponse as soon as it has been read off a
// stream, on the calling thread.
using SegmentCallback = std::function<void(const fovea::v1::SegmentResponse&)>;

// Insecure channels to a server or its replicas. Thread-safe: calls may
// run concurrently. Every call takes a deadline measured from the moment it
// starts; a failed call returns the server's (or gRPC's) status with the
// same code (absl and gRPC share the canonical codes, so
// absl::StatusCodeToString gives the gRPC name, e.g. "INVALID_ARGUMENT")
// and its message.
class FoveaClient {
 public:
  // Creates the channels to `target`: "HOST:PORT", a comma-separated list
  // of IP:PORT replicas, or any gRPC target URI such as dns:///NAME:PORT
  // (ChannelTarget). Perception calls go round robin to the replicas that
  // report SERVING and are retried on UNAVAILABLE (CreateBalancedChannel);
  // with none SERVING they fail at once with UNAVAILABLE, or wait with
  // `options.wait_for_ready`. Connecting is lazy: an unreachable server
  // shows up as UNAVAILABLE on the first call. INVALID_ARGUMENT from
  // ChannelTarget and Validate(options).
  static absl::StatusOr<std::unique_ptr<FoveaClient>> Connect(
      const std::string& target, const ClientOptions& options = {});

  // A client over an existing channel (e.g. an in-process one in tests),
  // used for every call as it is.
  FoveaClient(std::shared_ptr<grpc::Channel> channel,
              const ClientOptions& options);

  FoveaClient(const FoveaClient&) = delete;
  FoveaClient& operator=(const FoveaClient&) = delete;

  // grpc.health.v1.Health/Check for `service` ("" = the whole server,
  // "fovea.v1.Perception" = the perception service). The serving status
  // (SERVING, NOT_SERVING, ...) when the call succeeds; NOT_FOUND when the
  // server does not know `service`. Asks one replica, NOT_SERVING ones
  // included: with several, each call asks the next reachable one in turn
  // (CreateProbeChannel).
  absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus> Health(
      const std::string& service, absl::Duration deadline);

  absl::StatusOr<fovea::v1::GetCapabilitiesResponse> GetCapabilities(
      absl::Duration deadline);

  absl::StatusOr<fovea::v1::DetectResponse> Detect(
      const fovea::v1::DetectRequest& request, absl::Duration deadline);

  // Server-streaming calls: `on_message` runs once per message, in order,
  // as each arrives. Returns the stream's final status: OK after the server
  // closed it normally (the last message has `last` set), otherwise the
  // error (UNIMPLEMENTED from a server that has not built the method,
  // DEADLINE_EXCEEDED, ...), possibly after some messages.
  absl::Status Segment(const fovea::v1::SegmentRequest& request,
                       absl::Duration deadline,
                       const SegmentCallback& on_message);
  absl::Status SegmentIncremental(
      const fovea::v1::SegmentIncrementalRequest& request,
      absl::Duration deadline, const SegmentCallback& on_message);

  // A Track stream (track.proto): sends `options`, then the frames
  // `next_frame` gives until it returns nullopt, then half-closes;
  // `on_response` runs once per processed frame, in order. With `fps` 0
  // each frame is sent after the previous one's answer (none is skipped);
  // with `fps` > 0 frames are sent at that rate from another thread, as a
  // camera would, and the server answers the freshest (the others are
  // skipped: TrackResponse.frames_skipped). `deadline` bounds the whole
  // stream. Returns the stream's final status.
  absl::Status Track(
      const fovea::v1::TrackOptions& options,
      const std::function<std::optional<fovea::v1::TrackFrame>()>& next_frame,
      absl::Duration deadline,
      const std::function<void(const fovea::v1::TrackResponse&)>& on_response,
      double fps = 0.0);

 private:
  FoveaClient(std::shared_ptr<grpc::Channel> channel,
              std::shared_ptr<grpc::Channel> health_channel,
              const ClientOptions& options);

  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;         // Perception calls
  std::shared_ptr<grpc::Channel> health_channel_;  // Health calls
  std::unique_ptr<fovea::v1::Perception::Stub> perception_;
  std::unique_ptr<grpc::health::v1::Health::Stub> health_;
};

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_FOVEA_CLIENT_H_
