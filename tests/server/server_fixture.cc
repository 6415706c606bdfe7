#include "tests/server/server_fixture.h"

#include <new>
#include <stdexcept>
#include <utility>

#include "tests/server/test_util.h"

namespace fovea::server::testing {

void Gate::Close() {
  MutexLock lock(&mu_);
  open_ = false;
}

void Gate::CloseAtPass(int n) {
  MutexLock lock(&mu_);
  close_at_ = n;
  if (entered_ >= n) open_ = false;
}

void Gate::Open() {
  MutexLock lock(&mu_);
  open_ = true;
  close_at_ = 0;
}

int Gate::entered() const {
  MutexLock lock(&mu_);
  return entered_;
}

void Gate::Pass() {
  MutexLock lock(&mu_);
  ++entered_;
  if (entered_ == close_at_) open_ = false;
  mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return open_; });
}

void ServerTest::StartServer(ServerConfig config, bool wait_serving) {
  // Port 0: the server binds a port the kernel picks. A port FreePort()
  // found free can be taken, before the server binds it, as the source
  // port of another test's connection (CI failed so: EADDRINUSE).
  config.listen = "127.0.0.1:0";
  config.metrics_listen = "127.0.0.1:0";
  config.before_detect_job = [this] {
    gate_.Pass();
    ThrowIfAsked();
  };
  config.at_stage_boundary = [this] { stage_gate_.Pass(); };
  config.on_stream_cancelled = [this] { ++stream_cancels_; };
  absl::StatusOr<std::unique_ptr<FoveaServer>> server =
      FoveaServer::Start(std::move(config));
  ASSERT_TRUE(server.ok()) << server.status();
  server_ = *std::move(server);
  channel_ = grpc::CreateChannel("127.0.0.1:" + std::to_string(server_->port()),
                                 grpc::InsecureChannelCredentials());
  stub_ = v1::Perception::NewStub(channel_);
  if (!wait_serving) return;
  ASSERT_TRUE(
      WaitFor([this] { return HealthStatus(channel_, "") == "SERVING"; },
              kStartTimeout));
}

void ServerTest::TearDown() {
  gate_.Open();
  stage_gate_.Open();
  if (server_ != nullptr) server_->Shutdown(absl::Seconds(5));
}

ServerConfig ServerTest::DefaultConfig() {
  ServerConfig config;
  config.concurrency = 2;
  config.queue = 4;
  // SERVING at once: the warm-up Detect took 4.5 s per server under TSan,
  // 149 times a run. The tests of the warm-up itself turn it on.
  config.warm_up = false;
  return config;
}

grpc::Status ServerTest::Detect(const v1::DetectRequest& request,
                                v1::DetectResponse* response,
                                std::chrono::milliseconds deadline) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + deadline);
  return stub_->Detect(&context, request, response);
}

std::future<grpc::Status> ServerTest::DetectAsync(
    v1::DetectRequest request, std::chrono::milliseconds deadline) {
  return std::async(std::launch::async, [this, request, deadline] {
    v1::DetectResponse response;
    return Detect(request, &response, deadline);
  });
}

std::future<grpc::Status> ServerTest::StartHeldDetect(
    const v1::DetectRequest& request) {
  const int entered = gate_.entered();
  gate_.Close();
  std::future<grpc::Status> held = DetectAsync(request);
  EXPECT_TRUE(
      WaitFor([&] { return gate_.entered() == entered + 1; }, kCallTimeout))
      << "the Detect job never reached the gate";
  return held;
}

std::string ServerTest::Scrape() {
  if (server_ == nullptr) {
    ADD_FAILURE() << "no server to scrape";
    return "";
  }
  std::optional<std::string> text =
      HttpGet(server_->metrics_port(), "/metrics");
  EXPECT_TRUE(text.has_value());
  return text.value_or("");
}

double ServerTest::Handled(const std::string& text, const std::string& method,
                           const std::string& code) {
  return MetricValue(
             text, "grpc_server_handled_total",
             {"grpc_method=\"" + method + "\"", "grpc_code=\"" + code + "\""})
      .value_or(-1);
}

void ServerTest::ThrowIfAsked() {
  switch (throw_next_.exchange(Throw::kNothing)) {
    case Throw::kNothing:
      return;
    case Throw::kStdException:
      throw std::runtime_error("test hook: thrown on purpose");
    case Throw::kInt:
      throw 42;
    case Throw::kBadAlloc:
      throw std::bad_alloc();
  }
}

}  // namespace fovea::server::testing
