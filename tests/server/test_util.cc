#include "tests/server/test_util.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <map>
#include <sstream>
#include <thread>
#include <utility>

#include "core/base/mutex.h"
#include "core/synth/synth_scene.h"
#include "server/convert.h"

namespace fovea::server::testing {

int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  int port = 0;
  socklen_t len = sizeof(addr);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  close(fd);
  return port;
}

std::unique_ptr<v1::Perception::Stub> SlowReaderStub(int port) {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 1);
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  return v1::Perception::NewStub(
      grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port),
                                grpc::InsecureChannelCredentials(), args));
}

bool WaitFor(const std::function<bool()>& condition,
             std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (condition()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::optional<std::string> HttpGet(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return std::nullopt;
  timeval timeout{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    close(fd);
    return std::nullopt;
  }
  const std::string request =
      "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
  if (write(fd, request.data(), request.size()) !=
      static_cast<ssize_t>(request.size())) {
    close(fd);
    return std::nullopt;
  }
  std::string response;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fd, buffer, sizeof(buffer))) > 0) response.append(buffer, n);
  close(fd);
  if (response.rfind("HTTP/1.", 0) != 0 ||
      response.find(" 200 ") == std::string::npos) {
    return std::nullopt;
  }
  const size_t body = response.find("\r\n\r\n");
  if (body == std::string::npos) return std::nullopt;
  return response.substr(body + 4);
}

std::optional<double> MetricValue(const std::string& text,
                                  const std::string& name,
                                  const std::vector<std::string>& labels) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t name_end = line.find_first_of("{ ");
    if (name_end == std::string::npos || line.substr(0, name_end) != name) {
      continue;
    }
    std::string label_text;
    size_t value_start = name_end;
    if (line[name_end] == '{') {
      const size_t close = line.find('}', name_end);
      if (close == std::string::npos) continue;
      label_text = line.substr(name_end + 1, close - name_end - 1);
      value_start = close + 1;
    }
    bool all = true;
    for (const std::string& label : labels) {
      if (label_text.find(label) == std::string::npos) all = false;
    }
    if (!all) continue;
    return std::stod(line.substr(value_start));
  }
  return std::nullopt;
}

double MetricIncrease(const std::string& before, const std::string& after,
                      const std::string& name,
                      const std::vector<std::string>& labels) {
  return MetricValue(after, name, labels).value_or(0) -
         MetricValue(before, name, labels).value_or(0);
}

std::string HealthStatus(const std::shared_ptr<grpc::Channel>& channel,
                         const std::string& service) {
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) return std::to_string(status.error_code());
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(
      response.status());
}

namespace {

SyntheticRequest RenderSyntheticRequest(uint64_t seed, bool depth_16uc1) {
  synth::SynthScene scene = synth::GenerateScene(seed);
  SyntheticRequest out;
  out.request.set_request_id("synthetic-" + std::to_string(seed));
  *out.request.mutable_frame() =
      ToProtoFrame(scene.frame.frame,
                   depth_16uc1 ? DepthEncoding::k16UC1 : DepthEncoding::k32FC1);
  out.request.mutable_frame()->set_frame_id("camera");
  out.request.mutable_frame()->set_stamp_ns(1000 + seed);
  const cv::Mat& labels = scene.frame.labels;
  out.width = labels.cols;
  out.labels.reserve(static_cast<size_t>(labels.rows) * labels.cols);
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      out.labels.push_back(labels.at<int>(v, u));
    }
  }
  return out;
}

}  // namespace

SyntheticRequest MakeSyntheticRequest(uint64_t seed, bool depth_16uc1) {
  // Rendered once per process and copied: a test that builds several
  // requests of one scene spent most of its time rendering it again
  // (29 s of HostileRequestTest.NonFiniteIntrinsicsAreInvalidArgument-
  // NamingThem under ThreadSanitizer).
  static Mutex mu;
  static auto* rendered =
      new std::map<std::pair<uint64_t, bool>, SyntheticRequest>();
  MutexLock lock(&mu);
  auto [it, added] = rendered->try_emplace({seed, depth_16uc1});
  if (added) it->second = RenderSyntheticRequest(seed, depth_16uc1);
  return it->second;
}

}  // namespace fovea::server::testing
