#ifndef FOVEA_CLIENT_CHANNEL_H_
#define FOVEA_CLIENT_CHANNEL_H_

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "grpcpp/channel.h"
#include "grpcpp/support/channel_arguments.h"

// How a client reaches one Fovea server or several replicas of it: the
// gRPC target a --server value names, and the channel FoveaClient calls
// through. The channel spreads calls round robin over the replicas whose
// grpc.health.v1 watch for "fovea.v1.Perception" says SERVING (a warming
// up or draining replica gets none) and retries a call that fails with
// UNAVAILABLE before any reply arrived, on the next replica. (A server
// without grpc.health.v1 counts as SERVING: gRPC's rule.)

namespace fovea::client {

// The service name the channel's health watch asks each replica about.
inline constexpr char kHealthCheckedService[] = "fovea.v1.Perception";

struct ClientOptions {
  // Largest message sent or received, bytes, > 0. The server's default
  // maximum receive size is 64 MiB (a 1280x720 raw frame is about 6 MiB).
  // Also the most a call buffers to replay on a retry, so a frame of any
  // accepted size can be retried.
  int max_message_bytes = 64 * 1024 * 1024;
  // Wait for a replica to become ready (reachable and, for Perception
  // calls, SERVING) instead of failing at once with UNAVAILABLE while none
  // is. The call deadline still bounds the wait.
  bool wait_for_ready = false;
  // Attempts per call, 1..5 (gRPC's most), 1 = no retries. A call is
  // retried only when it failed with UNAVAILABLE (no replica reachable,
  // the connection dropped, the replica shut down) before the first reply
  // message or header arrived, within the call's deadline, after a
  // backoff of about 50 ms, doubling up to 1 s. Safe for every
  // fovea.v1.Perception method: Detect and GetCapabilities are idempotent,
  // and a Segment stream is only replayed before its first message (gRPC
  // commits the call once a reply arrives), so a caller never sees a
  // message twice.
  int max_attempts = 4;
  // TLS (PEM file contents, not paths): with `tls_root_certs` the channel
  // uses TLS and trusts these CAs; with `tls_cert_chain` and
  // `tls_private_key` too, it presents that client certificate (mutual
  // TLS). All empty: plaintext.
  std::string tls_root_certs;
  std::string tls_cert_chain;
  std::string tls_private_key;
};

// INVALID_ARGUMENT naming the first bad field of `options`.
absl::Status Validate(const ClientOptions& options);

// The gRPC target for `servers`, which is one of
//  - one target: "HOST:PORT" or any gRPC target URI, passed on unchanged.
//    A host name resolves through DNS to all its addresses, every one a
//    replica: "dns:///fovea.ns.svc.cluster.local:50051" (a Kubernetes
//    headless Service) reaches every pod. gRPC looks the name up again
//    only when a connection closes or fails (at most every 30 s), so a
//    replica added later gets calls from then on;
//  - a comma-separated list of IP:PORT replicas, "10.0.0.5:50051,
//    10.0.0.6:50051" or "[fd00::5]:50051,[fd00::6]:50051" (spaces around
//    entries are ignored), which becomes "ipv4:..." or "ipv6:...".
// INVALID_ARGUMENT, prefixed "server:", for an empty target, an empty list
// entry, an entry that is not an IP literal with a port 1..65535 (a list
// of host names cannot be expressed as one gRPC target: give one DNS name
// that resolves to every replica instead), a list mixing IPv4 and IPv6 or
// naming an address twice.
absl::StatusOr<std::string> ChannelTarget(const std::string& servers);

// The balanced channel described at the top to the replicas `servers`
// names (see ChannelTarget), over connections of its own (not shared with
// other channels to the same addresses). `arguments` may carry further
// channel arguments; the service config, message sizes and retry buffer
// are set here. Connecting is lazy. ChannelTarget's and Validate's errors.
absl::StatusOr<std::shared_ptr<grpc::Channel>> CreateBalancedChannel(
    const std::string& servers, const ClientOptions& options,
    grpc::ChannelArguments arguments = {});

// A channel for health checks to the same replicas: round robin over all
// of them, NOT_SERVING ones included (so a draining replica can say so),
// no retries. Errors as CreateBalancedChannel.
absl::StatusOr<std::shared_ptr<grpc::Channel>> CreateProbeChannel(
    const std::string& servers, const ClientOptions& options);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_CHANNEL_H_
