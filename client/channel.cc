#include "client/channel.h"

#include <arpa/inet.h>

#include <set>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "core/base/status_macros.h"
#include "grpc/grpc.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"

namespace fovea::client {
namespace {

// gRPC ignores a retry policy's maxAttempts above 5.
constexpr int kMostAttempts = 5;

// Retry backoff: the first retry after about kInitialBackoff, each next
// one kBackoffMultiplier times later, at most kMaxBackoff (gRPC adds
// +-20 % jitter).
constexpr char kInitialBackoff[] = "0.05s";
constexpr char kMaxBackoff[] = "1s";
constexpr int kBackoffMultiplier = 2;

enum class Family { kIpv4, kIpv6 };

// One list entry "IP:PORT" or "[IP]:PORT", trimmed; `position` is 1-based,
// for the message.
absl::StatusOr<Family> CheckListEntry(absl::string_view entry, int position,
                                      const std::string& servers) {
  const std::string where =
      absl::StrCat("server: entry ", position, " of \"", servers, "\"");
  if (entry.empty()) return absl::InvalidArgumentError(where + " is empty");
  const std::string quoted = absl::StrCat(where, " (\"", entry, "\")");
  absl::string_view host;
  absl::string_view port;
  Family family = Family::kIpv4;
  if (absl::StartsWith(entry, "[")) {
    const size_t close = entry.find("]:");
    if (close == absl::string_view::npos) {
      return absl::InvalidArgumentError(
          quoted + " is not [IPV6]:PORT (the port is missing)");
    }
    host = entry.substr(1, close - 1);
    port = entry.substr(close + 2);
    family = Family::kIpv6;
  } else {
    const size_t colon = entry.rfind(':');
    if (colon == absl::string_view::npos) {
      return absl::InvalidArgumentError(quoted + " has no port (want IP:PORT)");
    }
    host = entry.substr(0, colon);
    port = entry.substr(colon + 1);
    if (absl::StrContains(host, ':')) {
      return absl::InvalidArgumentError(
          quoted + " looks like an IPv6 address: write it as [IPV6]:PORT");
    }
  }
  int port_number = 0;
  if (!absl::SimpleAtoi(port, &port_number) || port_number < 1 ||
      port_number > 65535) {
    return absl::InvalidArgumentError(
        absl::StrCat(quoted, " has port \"", port, "\", want 1..65535"));
  }
  unsigned char address[16];
  const std::string host_text(host);
  if (inet_pton(family == Family::kIpv6 ? AF_INET6 : AF_INET, host_text.c_str(),
                address) != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        quoted,
        " is not an IP address: a list takes IP:PORT entries only; to "
        "reach replicas by name, give one DNS name that resolves to all "
        "of them, e.g. dns:///",
        host, ":", port));
  }
  return family;
}

// The service config of a channel (gRPC's service_config.proto as JSON).
// With `balanced`: health-checked round robin and the retry policy of
// ClientOptions::max_attempts; otherwise plain round robin.
std::string ServiceConfigJson(const ClientOptions& options, bool balanced) {
  if (!balanced) return R"({"loadBalancingConfig": [{"round_robin": {}}]})";
  std::string method_config;
  if (options.max_attempts > 1) {
    method_config = absl::StrCat(
        R"(, "methodConfig": [{"name": [{"service": "fovea.v1.Perception"}],)",
        R"( "retryPolicy": {"maxAttempts": )", options.max_attempts,
        R"(, "initialBackoff": ")", kInitialBackoff, R"(", "maxBackoff": ")",
        kMaxBackoff, R"(", "backoffMultiplier": )", kBackoffMultiplier,
        R"(, "retryableStatusCodes": ["UNAVAILABLE"]}}])");
  }
  return absl::StrCat(R"({"loadBalancingConfig": [{"round_robin": {}}],)",
                      R"( "healthCheckConfig": {"serviceName": ")",
                      kHealthCheckedService, R"("})", method_config, "}");
}

absl::StatusOr<std::shared_ptr<grpc::Channel>> CreateChannel(
    const std::string& servers, const ClientOptions& options,
    grpc::ChannelArguments arguments, bool balanced) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_ASSIGN_OR_RETURN(std::string target, ChannelTarget(servers));
  arguments.SetMaxReceiveMessageSize(options.max_message_bytes);
  arguments.SetMaxSendMessageSize(options.max_message_bytes);
  // A call larger than the retry buffer (gRPC's default: 256 KiB, less
  // than one 640x480 frame) is committed at once and never retried.
  arguments.SetInt(GRPC_ARG_PER_RPC_RETRY_BUFFER_SIZE,
                   options.max_message_bytes);
  // Subchannels (connections) of this channel only. gRPC 1.51 crashes
  // (SIGSEGV in ConnectedSubchannel::GetInitialCallSizeEstimate) when a
  // subchannel in TRANSIENT_FAILURE is shared by a health-checked channel
  // and one that is not, e.g. a plain channel to the same address.
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  // Our service config, whatever a DNS TXT record might say.
  arguments.SetInt(GRPC_ARG_SERVICE_CONFIG_DISABLE_RESOLUTION, 1);
  arguments.SetServiceConfigJSON(ServiceConfigJson(options, balanced));
  std::shared_ptr<grpc::ChannelCredentials> credentials =
      grpc::InsecureChannelCredentials();
  if (!options.tls_root_certs.empty()) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = options.tls_root_certs;
    ssl.pem_cert_chain = options.tls_cert_chain;
    ssl.pem_private_key = options.tls_private_key;
    credentials = grpc::SslCredentials(ssl);
  }
  std::shared_ptr<grpc::Channel> channel =
      grpc::CreateCustomChannel(target, credentials, arguments);
  if (channel == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("server: cannot create a channel to \"", target, "\""));
  }
  return channel;
}

}  // namespace

absl::Status Validate(const ClientOptions& options) {
  if (options.max_message_bytes <= 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_message_bytes: must be > 0, got ", options.max_message_bytes));
  }
  if (options.tls_cert_chain.empty() != options.tls_private_key.empty()) {
    return absl::InvalidArgumentError(
        "tls_cert_chain, tls_private_key: give both or neither");
  }
  if (!options.tls_cert_chain.empty() && options.tls_root_certs.empty()) {
    return absl::InvalidArgumentError(
        "tls_root_certs: needed with a client certificate (TLS)");
  }
  if (options.max_attempts < 1 || options.max_attempts > kMostAttempts) {
    return absl::InvalidArgumentError(absl::StrCat("max_attempts: must be 1..",
                                                   kMostAttempts, ", got ",
                                                   options.max_attempts));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> ChannelTarget(const std::string& servers) {
  const absl::string_view trimmed = absl::StripAsciiWhitespace(servers);
  if (trimmed.empty()) {
    return absl::InvalidArgumentError(
        "server: empty target (want HOST:PORT, IP:PORT,IP:PORT,... or "
        "dns:///NAME:PORT)");
  }
  if (!absl::StrContains(trimmed, ',') || absl::StartsWith(trimmed, "ipv4:") ||
      absl::StartsWith(trimmed, "ipv6:")) {
    return std::string(trimmed);
  }
  std::vector<std::string> entries;
  std::set<std::string> seen;
  std::set<Family> families;
  int position = 0;
  for (absl::string_view entry : absl::StrSplit(trimmed, ',')) {
    entry = absl::StripAsciiWhitespace(entry);
    FOVEA_ASSIGN_OR_RETURN(Family family,
                           CheckListEntry(entry, ++position, servers));
    if (!seen.emplace(entry).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("server: entry ", position, " of \"", servers,
                       "\" repeats \"", entry, "\""));
    }
    families.insert(family);
    entries.emplace_back(entry);
  }
  if (families.size() > 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "server: \"", servers,
        "\" mixes IPv4 and IPv6 addresses (a list is one family; a DNS name "
        "may resolve to both)"));
  }
  return absl::StrCat(*families.begin() == Family::kIpv6 ? "ipv6:" : "ipv4:",
                      absl::StrJoin(entries, ","));
}

absl::StatusOr<std::shared_ptr<grpc::Channel>> CreateBalancedChannel(
    const std::string& servers, const ClientOptions& options,
    grpc::ChannelArguments arguments) {
  return CreateChannel(servers, options, std::move(arguments),
                       /*balanced=*/true);
}

absl::StatusOr<std::shared_ptr<grpc::Channel>> CreateProbeChannel(
    const std::string& servers, const ClientOptions& options) {
  return CreateChannel(servers, options, grpc::ChannelArguments(),
                       /*balanced=*/false);
}

}  // namespace fovea::client
