"""How the client reaches one Fovea server or several replicas of it.

The same rules as the C++ client (client/channel.h): `servers` is one
gRPC target ("HOST:PORT", "dns:///NAME:PORT", ...) or a comma-separated
list of IP:PORT replicas. Calls go round robin to the replicas whose
grpc.health.v1 watch for "fovea.v1.Perception" says SERVING and are
retried on UNAVAILABLE before any reply arrived.
"""

import ipaddress
import json
from typing import Any, List, Tuple

HEALTH_CHECKED_SERVICE = "fovea.v1.Perception"
MOST_ATTEMPTS = 5  # gRPC ignores more


def channel_target(servers: str) -> str:
    """The gRPC target for `servers`; ValueError naming a bad entry.

    One target passes unchanged (a DNS name reaches every address it
    resolves to). A list of IP:PORT (or [IPV6]:PORT) entries becomes
    "ipv4:..." or "ipv6:..."; host names in a list, empty entries, bad
    ports, mixed families and repeats are refused.
    """
    trimmed = servers.strip()
    if not trimmed:
        raise ValueError("server: empty target (want HOST:PORT, "
                         "IP:PORT,IP:PORT,... or dns:///NAME:PORT)")
    if "," not in trimmed or trimmed.startswith(("ipv4:", "ipv6:")):
        return trimmed
    entries, families = [], set()
    for position, entry in enumerate(trimmed.split(","), start=1):
        entry = entry.strip()
        where = f'server: entry {position} of "{servers}"'
        if not entry:
            raise ValueError(f"{where} is empty")
        if entry.startswith("["):
            host, sep, port = entry[1:].partition("]:")
            if not sep:
                raise ValueError(f'{where} ("{entry}") is not [IPV6]:PORT')
        else:
            host, sep, port = entry.rpartition(":")
            if not sep:
                raise ValueError(f'{where} ("{entry}") has no port')
            if ":" in host:
                raise ValueError(f'{where} ("{entry}") looks like an IPv6 '
                                 "address: write it as [IPV6]:PORT")
        if not port.isdigit() or not 1 <= int(port) <= 65535:
            raise ValueError(f'{where} ("{entry}") has port "{port}", '
                             "want 1..65535")
        try:
            address = ipaddress.ip_address(host)
        except ValueError:
            raise ValueError(
                f'{where} ("{entry}") is not an IP address: a list takes '
                "IP:PORT entries only; to reach replicas by name, give one "
                f"DNS name that resolves to all of them, e.g. "
                f"dns:///{host}:{port}") from None
        if entry in entries:
            raise ValueError(f'{where} repeats "{entry}"')
        families.add(address.version)
        entries.append(entry)
    if len(families) > 1:
        raise ValueError(f'server: "{servers}" mixes IPv4 and IPv6 addresses')
    return ("ipv6:" if 6 in families else "ipv4:") + ",".join(entries)


def channel_options(max_message_bytes: int, max_attempts: int = 4,
                    balanced: bool = True) -> List[Tuple[str, Any]]:
    """grpc channel options: message sizes and the service config.

    balanced: round robin over the SERVING replicas with retries on
    UNAVAILABLE (max_attempts 1..5, 1 = none); otherwise plain round robin
    over every replica (for health checks, which must reach a NOT_SERVING
    one too).
    """
    if not 1 <= max_attempts <= MOST_ATTEMPTS:
        raise ValueError(f"max_attempts: must be 1..{MOST_ATTEMPTS}, "
                         f"got {max_attempts}")
    config = {"loadBalancingConfig": [{"round_robin": {}}]}
    if balanced:
        config["healthCheckConfig"] = {"serviceName": HEALTH_CHECKED_SERVICE}
        if max_attempts > 1:
            config["methodConfig"] = [{
                "name": [{"service": "fovea.v1.Perception"}],
                "retryPolicy": {
                    "maxAttempts": max_attempts,
                    "initialBackoff": "0.05s",
                    "maxBackoff": "1s",
                    "backoffMultiplier": 2,
                    "retryableStatusCodes": ["UNAVAILABLE"],
                },
            }]
    return [
        ("grpc.max_receive_message_length", max_message_bytes),
        ("grpc.max_send_message_length", max_message_bytes),
        # A call larger than the retry buffer (default 256 KiB) is never
        # retried.
        ("grpc.per_rpc_retry_buffer_size", max_message_bytes),
        # gRPC 1.51 crashes when a health-checked channel and a plain one
        # share a failing subchannel: keep this channel's connections apart.
        ("grpc.use_local_subchannel_pool", 1),
        ("grpc.service_config_disable_resolution", 1),
        ("grpc.service_config", json.dumps(config)),
    ]
