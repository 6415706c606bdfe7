#ifndef FOVEA_TESTS_SERVER_TEST_UTIL_H_
#define FOVEA_TESTS_SERVER_TEST_UTIL_H_

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fovea/v1/detect.pb.h"
#include "fovea/v1/perception.grpc.pb.h"
#include "grpc/health/v1/health.grpc.pb.h"

namespace fovea::server::testing {

// A TCP port on 127.0.0.1 that was free a moment ago (bind to port 0,
// read it, close). The server is then told to listen on it explicitly.
int FreePort();

// A stub on a channel to 127.0.0.1:`port` whose transport window is about
// one byte and never grows: a client that (almost) never reads.
std::unique_ptr<v1::Perception::Stub> SlowReaderStub(int port);

// Polls `condition` every few milliseconds until it holds or `timeout`
// passes; returns its last value.
bool WaitFor(const std::function<bool()>& condition,
             std::chrono::milliseconds timeout);

// The body of GET `path` from 127.0.0.1:`port` over plain HTTP/1.0, or
// nullopt when the request fails or the status is not 200.
std::optional<std::string> HttpGet(int port, const std::string& path);

// The value of the first sample of `name` in Prometheus text `text` whose
// labels include every `key="value"` in `labels`; nullopt when absent.
std::optional<double> MetricValue(const std::string& text,
                                  const std::string& name,
                                  const std::vector<std::string>& labels);

// How much that sample grew from Prometheus text `before` to `after`, an
// absent sample counting as 0. The metrics are the process's: the tests of
// one binary, run in one process, see each other's calls.
double MetricIncrease(const std::string& before, const std::string& after,
                      const std::string& name,
                      const std::vector<std::string>& labels);

// grpc.health.v1 Check for `service` on `channel`: "SERVING",
// "NOT_SERVING", ... or the gRPC error code's number as text when the
// call fails.
std::string HealthStatus(const std::shared_ptr<grpc::Channel>& channel,
                         const std::string& service);

// A Detect request for synthetic scene `seed` (synth::GenerateScene),
// as raw rgb8 plus 32FC1 (or 16UC1 in millimetres), with its labels.
struct SyntheticRequest {
  v1::DetectRequest request;
  std::vector<int> labels;  // row-major, width * height
  int width = 0;
};
SyntheticRequest MakeSyntheticRequest(uint64_t seed, bool depth_16uc1);

}  // namespace fovea::server::testing

#endif  // FOVEA_TESTS_SERVER_TEST_UTIL_H_
