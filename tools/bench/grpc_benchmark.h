#ifndef FOVEA_TOOLS_BENCH_GRPC_BENCHMARK_H_
#define FOVEA_TOOLS_BENCH_GRPC_BENCHMARK_H_

#include <string>

#include "tools/bench/bench_inputs.h"
#include "tools/bench/stage_benchmarks.h"

namespace fovea::bench {

// Registers "BM_DetectGrpc/default<suffix>" (a request without options: the
// server's defaults) and "BM_DetectGrpc/<ops><suffix>" for each of
// kDetectChannelSets (one level, MSR, no surface-edge split, as
// BM_Detect/<ops>):
// the scene's raw wire frame (rgb8 + 16UC1, the bytes BM_DecodeRaw
// decodes) sent as a DetectRequest over an insecure loopback channel to a
// fovea-server started in this process (server/server.h, concurrency 1,
// no metrics endpoint, logging at warnings), one blocking call at a time.
// Compared with BM_Detect/<ops> it adds decoding, serialisation, the
// transport, the work queue and response conversion: the service's cost.
// The server starts on first use, after its warm-up, and stops at
// StopGrpcServer. `scenes` must outlive the run.
// The loopback server's --threads_per_request (default 1, as the
// in-process cases); call before the first gRPC case runs.
void SetGrpcThreadsPerRequest(int threads);

void RegisterGrpcBenchmarks(const SceneList* scenes,
                            const std::string& set_name,
                            const std::string& suffix,
                            const SweepOptions& sweep);

// Stops the in-process server if one was started.
void StopGrpcServer();

}  // namespace fovea::bench

#endif  // FOVEA_TOOLS_BENCH_GRPC_BENCHMARK_H_
