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
  int clients = 4;              // concurrent callers, each with its own channel
  int requests = 200;           // in all, shared among the clients
  double max_seconds = 60;      // stop issuing after this long
  std::string rpc = "detect";   // detect | segment | segment-incremental
  uint64_t synthetic_seed = 3;  // the frame sent (core/synth)
  double deadline_seconds = 10;  // per call
};

struct LoadReport {
  int calls = 0;
  double seconds = 0;
  double throughput = 0;  // calls per second
  double p50_ms = 0, p99_ms = 0;
  double first_object_p50_ms = 0;    // streams only; 0 otherwise
  std::map<std::string, int> codes;  // gRPC code name -> calls
};

// INVALID_ARGUMENT for a non-loopback server, a bad list or bad numbers.
absl::StatusOr<LoadReport> RunLoad(const LoadOptions& options);

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_LOAD_H_
