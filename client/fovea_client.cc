#include "client/fovea_client.h"

#include <thread>
#include <utility>

#include "absl/memory/memory.h"
#include "absl/time/clock.h"
#include "core/base/status_macros.h"
#include "grpcpp/client_context.h"

namespace fovea::client {
namespace {

// gRPC and absl number the canonical codes alike (both follow
// google.rpc.Code), so the code carries over unchanged.
absl::Status ToAbslStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      status.error_message());
}

// Prepares `context` for one call that must end within `deadline`.
void PrepareContext(absl::Duration deadline, const ClientOptions& options,
                    grpc::ClientContext& context) {
  context.set_deadline(absl::ToChronoTime(absl::Now() + deadline));
  context.set_wait_for_ready(options.wait_for_ready);
}

template <typename Reader>
absl::Status DrainStream(Reader& reader, const SegmentCallback& on_message) {
  fovea::v1::SegmentResponse message;
  while (reader.Read(&message)) {
    on_message(message);
    message.Clear();
  }
  return ToAbslStatus(reader.Finish());
}

}  // namespace

absl::StatusOr<std::unique_ptr<FoveaClient>> FoveaClient::Connect(
    const std::string& target, const ClientOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(std::shared_ptr<grpc::Channel> channel,
                         CreateBalancedChannel(target, options));
  FOVEA_ASSIGN_OR_RETURN(std::shared_ptr<grpc::Channel> health_channel,
                         CreateProbeChannel(target, options));
  return absl::WrapUnique(
      new FoveaClient(std::move(channel), std::move(health_channel), options));
}

FoveaClient::FoveaClient(std::shared_ptr<grpc::Channel> channel,
                         const ClientOptions& options)
    : FoveaClient(channel, channel, options) {}

FoveaClient::FoveaClient(std::shared_ptr<grpc::Channel> channel,
                         std::shared_ptr<grpc::Channel> health_channel,
                         const ClientOptions& options)
    : options_(options),
      channel_(std::move(channel)),
      health_channel_(std::move(health_channel)),
      perception_(fovea::v1::Perception::NewStub(channel_)),
      health_(grpc::health::v1::Health::NewStub(health_channel_)) {}

absl::StatusOr<grpc::health::v1::HealthCheckResponse::ServingStatus>
FoveaClient::Health(const std::string& service, absl::Duration deadline) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = health_->Check(&context, request, &response);
  if (!status.ok()) return ToAbslStatus(status);
  return response.status();
}

absl::StatusOr<fovea::v1::GetCapabilitiesResponse> FoveaClient::GetCapabilities(
    absl::Duration deadline) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  fovea::v1::GetCapabilitiesResponse response;
  const grpc::Status status = perception_->GetCapabilities(
      &context, fovea::v1::GetCapabilitiesRequest(), &response);
  if (!status.ok()) return ToAbslStatus(status);
  return response;
}

absl::StatusOr<fovea::v1::DetectResponse> FoveaClient::Detect(
    const fovea::v1::DetectRequest& request, absl::Duration deadline) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  fovea::v1::DetectResponse response;
  const grpc::Status status = perception_->Detect(&context, request, &response);
  if (!status.ok()) return ToAbslStatus(status);
  return response;
}

absl::Status FoveaClient::Segment(const fovea::v1::SegmentRequest& request,
                                  absl::Duration deadline,
                                  const SegmentCallback& on_message) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  std::unique_ptr<grpc::ClientReader<fovea::v1::SegmentResponse>> reader =
      perception_->Segment(&context, request);
  return DrainStream(*reader, on_message);
}

absl::Status FoveaClient::SegmentIncremental(
    const fovea::v1::SegmentIncrementalRequest& request,
    absl::Duration deadline, const SegmentCallback& on_message) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  std::unique_ptr<grpc::ClientReader<fovea::v1::SegmentResponse>> reader =
      perception_->SegmentIncremental(&context, request);
  return DrainStream(*reader, on_message);
}

absl::Status FoveaClient::Track(
    const fovea::v1::TrackOptions& options,
    const std::function<std::optional<fovea::v1::TrackFrame>()>& next_frame,
    absl::Duration deadline,
    const std::function<void(const fovea::v1::TrackResponse&)>& on_response,
    double fps) {
  grpc::ClientContext context;
  PrepareContext(deadline, options_, context);
  std::unique_ptr<grpc::ClientReaderWriter<fovea::v1::TrackRequest,
                                           fovea::v1::TrackResponse>>
      stream = perception_->Track(&context);
  fovea::v1::TrackRequest first;
  *first.mutable_options() = options;
  fovea::v1::TrackResponse response;
  if (!stream->Write(first)) return ToAbslStatus(stream->Finish());
  if (fps <= 0.0) {
    // Lockstep: a frame, its answer, the next frame.
    while (std::optional<fovea::v1::TrackFrame> frame = next_frame()) {
      fovea::v1::TrackRequest request;
      *request.mutable_frame() = *std::move(frame);
      if (!stream->Write(request) || !stream->Read(&response)) break;
      on_response(response);
    }
    stream->WritesDone();
    while (stream->Read(&response)) on_response(response);
    return ToAbslStatus(stream->Finish());
  }
  // A camera: frames at `fps` whatever the answers do.
  std::thread writer([&] {
    const absl::Duration period = absl::Seconds(1.0 / fps);
    absl::Time next = absl::Now();
    while (std::optional<fovea::v1::TrackFrame> frame = next_frame()) {
      absl::SleepFor(next - absl::Now());
      next += period;
      fovea::v1::TrackRequest request;
      *request.mutable_frame() = *std::move(frame);
      if (!stream->Write(request)) break;
    }
    stream->WritesDone();
  });
  while (stream->Read(&response)) on_response(response);
  writer.join();
  return ToAbslStatus(stream->Finish());
}

}  // namespace fovea::client
