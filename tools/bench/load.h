#ifndef FOVEA_TOOLS_BENCH_LOAD_H_
#define FOVEA_TOOLS_BENCH_LOAD_H_

#include <map>
#include <string>

#include "absl/status/statusor.h"

namespace fovea::bench {

// `fovea-bench load`: closed-loop load on a running server, or several
// replicas of it, over loopback.
struct LoadOptions {
  // HOST:PORT or a comma-separated list of replicas IP:PORT,IP:PORT,...
  // (client/channel.h), every one on loopback. Each client spreads its
  // calls round robin over the replicas that report SERVING and retries a
  // call that fails with UNAVAILABLE, as FoveaClient does.
  std::string server = "127.0.0.1:50051";
  int clients = 4;          // concurrent callers, each with its own channel
  int requests = 200;       // in all, shared among the clients
  double max_seconds = 60;  // stop issuing after this long
  // detect | segment | segment-incremental | track
  std::string rpc = "detect";
  uint64_t synthetic_seed = 3;   // the frame sent (core/synth)
  double deadline_seconds = 10;  // per call
  // > 0: a fixed time instead (requests is then no limit): each client
  // calls until it has passed, and goodput is OK calls over that time.
  double duration_seconds = 0;
  // After a refusal (RESOURCE_EXHAUSTED, UNAVAILABLE) a client waits a
  // random time up to its backoff before the next call, as a gRPC retry
  // policy does: 0.1 s at first, doubling up to 1 s, back to 0.1 s after
  // an OK call. Without it a refused client calls again at once.
  bool backoff = false;
  // rpc "track": each client holds one Track stream (reopened after a
  // refusal) and sends a drifting camera's frames, one after each answer;
  // each answered frame counts as an OK call.
};

struct LoadReport {
  int calls = 0;
  double seconds = 0;
  double throughput = 0;  // calls per second
  double p50_ms = 0, p99_ms = 0;
  double first_object_p50_ms = 0;    // streams only; 0 otherwise
  std::map<std::string, int> codes;  // gRPC code name -> calls
  int ok = 0;
  double goodput = 0;  // OK calls per second
  // Refused calls (RESOURCE_EXHAUSTED, UNAVAILABLE) and how long the
  // client waited for each refusal, ms.
  int refused = 0;
  double refusal_p50_ms = 0, refusal_p99_ms = 0;
};

// INVALID_ARGUMENT for a non-loopback server, a bad list or bad numbers.
absl::StatusOr<LoadReport> RunLoad(const LoadOptions& options);

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_LOAD_H_
