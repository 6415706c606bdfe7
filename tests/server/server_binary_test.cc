// The fovea-server executable: --help, bad flags, and a clean exit on
// SIGTERM, idle or with calls in flight.

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/test_util.h"

#ifndef FOVEA_SERVER_BINARY
#error "FOVEA_SERVER_BINARY must name the built fovea-server"
#endif

namespace fovea::server {
namespace {

using ::fovea::server::testing::FreePort;
using ::fovea::server::testing::HealthStatus;
using ::fovea::server::testing::HttpGet;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

// Starts fovea-server with `args` (and a soft and hard RLIMIT_NOFILE of
// `nofile` when positive); returns its pid.
pid_t Spawn(const std::vector<std::string>& args, int nofile = 0) {
  std::vector<char*> argv;
  std::string binary = FOVEA_SERVER_BINARY;
  argv.push_back(binary.data());
  std::vector<std::string> copies = args;
  for (std::string& arg : copies) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (nofile > 0) {
      const rlimit limit{static_cast<rlim_t>(nofile),
                         static_cast<rlim_t>(nofile)};
      if (setrlimit(RLIMIT_NOFILE, &limit) != 0) _exit(126);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Waits (bounded) for `pid` to exit; its wait status, or -1.
int WaitExit(pid_t pid, std::chrono::milliseconds timeout) {
  int status = -1;
  const bool exited =
      WaitFor([&] { return waitpid(pid, &status, WNOHANG) == pid; }, timeout);
  return exited ? status : -1;
}

// Output and wait status of fovea-server run with `args` to completion;
// `env` ("NAME=value ", shell syntax) goes before the command.
std::pair<std::string, int> RunToCompletion(const std::string& args,
                                            const std::string& env = "") {
  const std::string command =
      env + std::string(FOVEA_SERVER_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    output.append(buffer, n);
  }
  const int status = pclose(pipe);
  return {output, status};
}

TEST(ServerBinaryTest, HelpListsEveryFlagWithItsDefault) {
  const auto [output, status] = RunToCompletion("--help");
  for (const char* flag :
       {"--listen", "--metrics_listen", "--concurrency", "--queue",
        "--max_message_bytes", "--max_width", "--max_height",
        "--grace_period_s", "--log_level", "--models_dir"}) {
    EXPECT_THAT(output, HasSubstr(flag));
  }
  for (const char* flag : {"--memory_quota_mb", "--stream_stall_timeout_s",
                           "--handshake_timeout_s"}) {
    EXPECT_THAT(output, HasSubstr(flag));
  }
  EXPECT_THAT(output, HasSubstr("default: 512"));
  EXPECT_THAT(output, HasSubstr("default: \"0.0.0.0:50051\""));
}

TEST(ServerBinaryTest, BadFlagValueExitsNonZeroNamingIt) {
  const auto [output, status] =
      RunToCompletion("--concurrency=0 --metrics_listen=");
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_THAT(output, HasSubstr("--concurrency"));
}

TEST(ServerBinaryTest, FlagsComeFromTheEnvironmentAndTheCommandLineWins) {
  // FOVEA_MODELS_DIR points at a folder without models: start-up fails
  // naming it, which proves the variable was read.
  const std::string dir =
      ::testing::TempDir() + "/fovea_env_models_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  {
    const auto [output, status] =
        RunToCompletion("--metrics_listen=", "FOVEA_MODELS_DIR=" + dir + " ");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_THAT(output, HasSubstr(dir));
  }
  {
    // A bad value names the variable, not a flag the user never typed.
    const auto [output, status] =
        RunToCompletion("--metrics_listen=", "FOVEA_CONCURRENCY=many ");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    EXPECT_THAT(output, HasSubstr("FOVEA_CONCURRENCY"));
  }
  {
    // Every flag of the server comes from the environment, the last one
    // defined as well as the first (the list is the flags' own): a number
    // that does not parse is refused naming its variable, an address
    // that does not resolve is the one listened on.
    for (const std::string variable :
         {"FOVEA_HANDSHAKE_TIMEOUT_S", "FOVEA_RECORD_SAMPLE"}) {
      const auto [output, status] =
          RunToCompletion("--metrics_listen=", variable + "=not-a-number ");
      EXPECT_TRUE(WIFEXITED(status)) << variable;
      EXPECT_EQ(WEXITSTATUS(status), 2) << variable << ": " << output;
      EXPECT_THAT(output, HasSubstr(variable));
    }
    const auto [output, status] =
        RunToCompletion("--metrics_listen=", "FOVEA_LISTEN=no-such-host ");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_THAT(output, HasSubstr("cannot listen on 'no-such-host'"));
  }
  {
    // The command line overrides the environment: a good log level from
    // the environment, a bad one on the command line, and the bad one is
    // what start-up rejects.
    const auto [output, status] =
        RunToCompletion("--log_level=bogus --metrics_listen=",
                        "FOVEA_LOG_LEVEL=info FOVEA_MODELS_DIR=" + dir + " ");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    EXPECT_THAT(output, HasSubstr("bogus"));
  }
  std::filesystem::remove_all(dir);
}

TEST(ServerBinaryTest, MissingOrCorruptModelsStopStartUpNamingTheFile) {
  const std::string dir =
      ::testing::TempDir() + "/fovea_models_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  {
    const auto [output, status] =
        RunToCompletion("--models_dir=" + dir + " --metrics_listen=");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_THAT(output, HasSubstr("cos_svm.txt is missing"));
    EXPECT_THAT(output, HasSubstr("fovea-train cos"));
  }
  {
    std::ofstream(dir + "/cos_svm.txt") << "fovea-linear-svm 1\nkind cos\n"
                                           "features a b\nweights 1 x\n";
    const auto [output, status] =
        RunToCompletion("--models_dir=" + dir + " --metrics_listen=");
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_THAT(output, HasSubstr("is not a COS model"));
    EXPECT_THAT(output, HasSubstr("not a finite number"));
  }
  std::filesystem::remove_all(dir);
}

// A fovea-server process on loopback, started with `flags` plus --listen
// and --metrics_listen on free ports.
struct ServerProcess {
  pid_t pid = -1;
  std::string target;  // host:port of the gRPC server
  int metrics_port = 0;
};

// Starts fovea-server and waits (up to 60 s) for health SERVING on both
// names. Fails the test (ADD_FAILURE) and returns pid -1 when it exits
// early or never serves.
ServerProcess StartServing(const std::vector<std::string>& flags,
                           int nofile = 0) {
  ServerProcess server;
  const int port = FreePort();
  server.metrics_port = FreePort();
  server.target = "127.0.0.1:" + std::to_string(port);
  std::vector<std::string> args = flags;
  args.push_back("--listen=" + server.target);
  args.push_back("--metrics_listen=127.0.0.1:" +
                 std::to_string(server.metrics_port));
  server.pid = Spawn(args, nofile);
  if (server.pid <= 0) {
    ADD_FAILURE() << "fork failed";
    return server;
  }
  // A fresh channel per attempt: a channel that tried before the server
  // listened may wait out gRPC's reconnect backoff (seconds).
  auto health = [&server](const std::string& service) {
    return HealthStatus(
        grpc::CreateChannel(server.target, grpc::InsecureChannelCredentials()),
        service);
  };
  int status = 0;
  bool exited = false;
  const bool serving = WaitFor(
      [&] {
        exited = waitpid(server.pid, &status, WNOHANG) == server.pid;
        return exited || health("fovea.v1.Perception") == "SERVING";
      },
      std::chrono::seconds(60));
  if (exited || !serving || health("") != "SERVING") {
    ADD_FAILURE() << (exited ? "exited early, wait status " +
                                   std::to_string(status)
                             : std::string("not SERVING within 60 s"));
    if (!exited) {
      kill(server.pid, SIGKILL);
      waitpid(server.pid, &status, 0);
    }
    server.pid = -1;
  }
  return server;
}

// Sends SIGTERM and expects exit code 0 within 30 s.
void ExpectCleanExitOnSigterm(pid_t pid) {
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  const int status = WaitExit(pid, std::chrono::seconds(30));
  if (status == -1) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  ASSERT_NE(status, -1) << "did not exit within 30 s of SIGTERM";
  EXPECT_TRUE(WIFEXITED(status)) << "wait status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// A TCP connection to `port` on loopback that sends nothing; -1 on failure.
int SilentConnection(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) !=
      0) {
    close(fd);
    return -1;
  }
  return fd;
}

bool DetectOk(const std::string& target, std::chrono::milliseconds deadline) {
  auto stub = v1::Perception::NewStub(
      grpc::CreateChannel(target, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + deadline);
  v1::DetectResponse response;
  return stub
      ->Detect(&context, MakeSyntheticRequest(1, false).request, &response)
      .ok();
}

// More silent connections than the server has descriptors (256): it keeps
// some descriptors free (metrics still scrape), does not spin, drops the
// silent connections after the handshake timeout, and serves a new client
// within seconds of the flood ending. (gRPC 1.51 alone never accepted
// again after its first EMFILE.)
TEST(ServerBinaryTest, FloodOfSilentConnectionsLeavesTheListenerAlive) {
  const ServerProcess server = StartServing(
      {"--concurrency=1", "--handshake_timeout_s=2", "--grace_period_s=2"},
      256);
  ASSERT_GT(server.pid, 0);
  const int port =
      std::stoi(server.target.substr(server.target.rfind(':') + 1));
  std::vector<int> flood;
  for (int i = 0; i < 300; ++i) {
    const int fd = SilentConnection(port);
    if (fd >= 0) flood.push_back(fd);
  }
  EXPECT_GE(flood.size(), 250u);
  // Metrics still answer while the flood is on, and count the refusals
  // (updated every second).
  EXPECT_TRUE(WaitFor(
      [&] {
        const std::optional<std::string> metrics =
            HttpGet(server.metrics_port, "/metrics");
        return metrics.has_value() &&
               MetricValue(*metrics, "fovea_connections_refused_total", {})
                       .value_or(0) > 0;
      },
      std::chrono::seconds(10)));
  // The silent ones are dropped after the handshake timeout; then a client
  // is served even with the flood's sockets still open on this side.
  EXPECT_TRUE(WaitFor(
      [&] { return DetectOk(server.target, std::chrono::milliseconds(2000)); },
      std::chrono::seconds(30)));
  for (const int fd : flood) close(fd);
  EXPECT_TRUE(DetectOk(server.target, std::chrono::milliseconds(5000)));
  ExpectCleanExitOnSigterm(server.pid);
}

// The reflection service's one method, called with an empty request
// stream: its status.
grpc::StatusCode ReflectionCallStatus(const std::string& target) {
  grpc::GenericStub stub(
      grpc::CreateChannel(target, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(10));
  grpc::CompletionQueue queue;
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
      stub.PrepareCall(&context,
                       "/grpc.reflection.v1alpha.ServerReflection/"
                       "ServerReflectionInfo",
                       &queue);
  void* tag = nullptr;
  bool ok = false;
  call->StartCall(reinterpret_cast<void*>(1));
  queue.Next(&tag, &ok);
  call->WritesDone(reinterpret_cast<void*>(2));
  queue.Next(&tag, &ok);
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(3));
  queue.Next(&tag, &ok);
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  return status.error_code();
}

TEST(ServerBinaryTest, ReflectionIsOnUnlessTurnedOff) {
  for (const bool on : {true, false}) {
    const ServerProcess server = StartServing(
        {"--concurrency=1", on ? "--reflection=true" : "--reflection=false"});
    ASSERT_GT(server.pid, 0);
    EXPECT_EQ(ReflectionCallStatus(server.target),
              on ? grpc::StatusCode::OK : grpc::StatusCode::UNIMPLEMENTED);
    ExpectCleanExitOnSigterm(server.pid);
  }
}

// A CA, a server certificate for 127.0.0.1 and a client certificate, made
// with openssl in a fresh folder; empty when openssl is missing or fails.
std::string MakeCertificates() {
  char pattern[] = "/tmp/fovea_tls_XXXXXX";
  const char* dir = mkdtemp(pattern);
  if (dir == nullptr) return "";
  const std::string d = dir;
  // Written to a file: the shell std::system runs would expand $who.
  {
    std::ofstream script(d + "/make.sh");
    script << "set -e\ncd '" << d << "'\n"
           << "openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key "
              "-out ca.pem -days 1 -subj /CN=fovea-test-ca\n"
           << "for who in server client; do\n"
              "  openssl req -newkey rsa:2048 -nodes -keyout $who.key "
              "-out $who.csr -subj /CN=$who\n"
              "  printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' "
              "> $who.ext\n"
              "  openssl x509 -req -in $who.csr -CA ca.pem -CAkey ca.key "
              "-CAcreateserial -out $who.pem -days 1 -extfile $who.ext\n"
              "done\n";
  }
  const std::string command = "bash '" + d + "/make.sh' >/dev/null 2>&1";
  return std::system(command.c_str()) == 0 ? d : "";
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

grpc::StatusCode DetectWith(const std::string& target,
                            std::shared_ptr<grpc::ChannelCredentials> creds) {
  grpc::ChannelArguments args;
  args.SetMaxSendMessageSize(64 << 20);
  auto stub =
      v1::Perception::NewStub(grpc::CreateCustomChannel(target, creds, args));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::seconds(10));
  v1::DetectResponse response;
  return stub
      ->Detect(&context, MakeSyntheticRequest(1, false).request, &response)
      .error_code();
}

// With a certificate, a key and a client CA the port speaks mutual TLS
// only: a client with a certificate the CA signed is served; one without a
// certificate, or in plaintext, is not.
TEST(ServerBinaryTest, MutualTlsServesOnlyClientsWithACertificate) {
#if defined(__SANITIZE_THREAD__)
  // Under ThreadSanitizer the TLS server's gRPC shutdown did not return
  // within 30 s after the refused handshakes (0.6 ms in a Release build);
  // not yet understood, see docs/hostile-clients.md.
  GTEST_SKIP() << "TLS shutdown hangs under ThreadSanitizer (open question)";
#endif
  const std::string dir = MakeCertificates();
  if (dir.empty()) GTEST_SKIP() << "openssl could not make certificates";
  const int port = FreePort();
  const std::string target = "127.0.0.1:" + std::to_string(port);
  const pid_t pid = Spawn(
      {"--listen=" + target, "--metrics_listen=", "--concurrency=1",
       "--tls_cert=" + dir + "/server.pem", "--tls_key=" + dir + "/server.key",
       "--tls_client_ca=" + dir + "/ca.pem"});
  ASSERT_GT(pid, 0);
  grpc::SslCredentialsOptions with_cert;
  with_cert.pem_root_certs = ReadAll(dir + "/ca.pem");
  with_cert.pem_cert_chain = ReadAll(dir + "/client.pem");
  with_cert.pem_private_key = ReadAll(dir + "/client.key");
  grpc::SslCredentialsOptions without_cert;
  without_cert.pem_root_certs = with_cert.pem_root_certs;
  EXPECT_TRUE(WaitFor(
      [&] {
        return DetectWith(target, grpc::SslCredentials(with_cert)) ==
               grpc::StatusCode::OK;
      },
      std::chrono::seconds(60)));
  EXPECT_NE(DetectWith(target, grpc::SslCredentials(without_cert)),
            grpc::StatusCode::OK);
  EXPECT_NE(DetectWith(target, grpc::InsecureChannelCredentials()),
            grpc::StatusCode::OK);
  ExpectCleanExitOnSigterm(pid);
  std::filesystem::remove_all(dir);
}

TEST(ServerBinaryTest, BadTlsFlagsStopStartUpNamingThem) {
  const auto [output, status] = RunToCompletion("--tls_cert=/nonexistent.pem");
  EXPECT_NE(status, 0);
  EXPECT_THAT(output, HasSubstr("--tls_cert"));
}

TEST(ServerBinaryTest, ExitsZeroOnSigtermAfterServing) {
  const ServerProcess server =
      StartServing({"--concurrency=1", "--grace_period_s=5"});
  ASSERT_GT(server.pid, 0);
  ExpectCleanExitOnSigterm(server.pid);
}

// Several Detects at once on one worker, so that some are computing or
// queued when SIGTERM arrives: each ends OK (finished within the grace
// period) or UNAVAILABLE / CANCELLED (refused or cut off by the shutdown),
// never another error, and the process exits 0.
TEST(ServerBinaryTest, SigtermWithCallsInFlightLetsThemEndAndExitsZero) {
  constexpr int kCalls = 12;
  const ServerProcess server =
      StartServing({"--concurrency=1", "--queue=" + std::to_string(kCalls),
                    "--grace_period_s=20", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  auto channel =
      grpc::CreateChannel(server.target, grpc::InsecureChannelCredentials());
  auto stub = v1::Perception::NewStub(channel);
  const v1::DetectRequest request = MakeSyntheticRequest(1, false).request;
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < kCalls; ++i) {
    calls.push_back(std::async(std::launch::async, [&stub, &request] {
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() +
                           std::chrono::seconds(60));
      v1::DetectResponse response;
      return stub->Detect(&context, request, &response);
    }));
  }
  // Signal once the server holds several calls (computing or queued).
  double inflight = 0;
  const bool busy = WaitFor(
      [&] {
        const std::optional<std::string> text =
            HttpGet(server.metrics_port, "/metrics");
        inflight =
            text.has_value()
                ? MetricValue(*text, "fovea_inflight_requests", {}).value_or(0)
                : 0;
        return inflight >= 2;
      },
      std::chrono::seconds(30));
  EXPECT_TRUE(busy) << "the server never held 2 calls at once";
  ExpectCleanExitOnSigterm(server.pid);

  int ok = 0;
  for (std::future<grpc::Status>& call : calls) {
    const grpc::Status status = call.get();
    if (status.ok()) ++ok;
    EXPECT_TRUE(status.ok() ||
                status.error_code() == grpc::StatusCode::UNAVAILABLE ||
                status.error_code() == grpc::StatusCode::CANCELLED)
        << status.error_code() << ": " << status.error_message();
  }
  // The calls in flight at the signal had 20 s to finish: they did.
  EXPECT_GE(ok, static_cast<int>(inflight));
  RecordProperty("inflight_at_sigterm", static_cast<int>(inflight));
  RecordProperty("ok", ok);
}

// Streams held in flight at SIGTERM: each client reads nothing until the
// server has begun to shut down, and each message carries a 1 MiB
// request_id over a channel whose HTTP/2 window stays at 64 KiB, so no
// stream can finish (nor its job get past its third message) before the
// signal, whatever the machine's speed.
constexpr size_t kBigRequestIdBytes = 1 << 20;

struct HeldStream {
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientReader<v1::SegmentResponse>> reader;
};

// Opens `count` streams on `server`, alternately Segment and
// SegmentIncremental, and waits until the server holds all of them.
std::vector<HeldStream> OpenHeldStreams(const ServerProcess& server,
                                        v1::Perception::Stub& stub, int count) {
  const v1::Frame frame = MakeSyntheticRequest(3, false).request.frame();
  v1::SegmentRequest segment;
  segment.set_request_id(std::string(kBigRequestIdBytes, 'x'));
  *segment.mutable_frame() = frame;
  v1::SegmentIncrementalRequest incremental;
  incremental.set_request_id(segment.request_id());
  *incremental.mutable_frame() = frame;
  std::vector<HeldStream> streams(count);
  for (int i = 0; i < count; ++i) {
    streams[i].context = std::make_unique<grpc::ClientContext>();
    streams[i].context->set_deadline(std::chrono::system_clock::now() +
                                     std::chrono::seconds(60));
    streams[i].reader =
        i % 2 == 0
            ? stub.Segment(streams[i].context.get(), segment)
            : stub.SegmentIncremental(streams[i].context.get(), incremental);
  }
  EXPECT_TRUE(WaitFor(
      [&] {
        const std::optional<std::string> text =
            HttpGet(server.metrics_port, "/metrics");
        return text.has_value() &&
               MetricValue(*text, "fovea_inflight_requests", {}) == count;
      },
      std::chrono::seconds(30)))
      << "the server never held all " << count << " streams";
  return streams;
}

// How one stream ended.
struct StreamEnd {
  grpc::Status status;
  bool last = false;  // its last message had `last` set
};

// Reads every stream to its end, all at once (a stream queued behind an
// unread one would wait for it otherwise).
std::vector<StreamEnd> ReadAllStreams(std::vector<HeldStream>& streams) {
  std::vector<std::future<StreamEnd>> reads;
  for (HeldStream& stream : streams) {
    reads.push_back(std::async(std::launch::async, [&stream] {
      StreamEnd end;
      v1::SegmentResponse message;
      while (stream.reader->Read(&message)) end.last = message.last();
      end.status = stream.reader->Finish();
      return end;
    }));
  }
  std::vector<StreamEnd> ends;
  for (std::future<StreamEnd>& read : reads) ends.push_back(read.get());
  return ends;
}

// A stub whose channel keeps HTTP/2's initial 64 KiB receive window (no
// BDP probing, which grows it while a client reads).
std::unique_ptr<v1::Perception::Stub> SmallWindowStub(
    const std::string& target) {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  return v1::Perception::NewStub(grpc::CreateCustomChannel(
      target, grpc::InsecureChannelCredentials(), args));
}

// Two streams computing (each blocked writing to its unread client) and
// six queued at SIGTERM, with a grace period long enough: once their
// clients read, every one completes with its last message, and the
// process exits 0.
TEST(ServerBinaryTest, SigtermWithStreamsInFlightLetsThemCompleteAndExitsZero) {
  constexpr int kStreams = 8;
  const ServerProcess server =
      StartServing({"--concurrency=2", "--queue=" + std::to_string(kStreams),
                    "--grace_period_s=30", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  const auto stub = SmallWindowStub(server.target);
  std::vector<HeldStream> streams = OpenHeldStreams(server, *stub, kStreams);

  ASSERT_EQ(kill(server.pid, SIGTERM), 0);
  // Shutting down: health leaves SERVING (NOT_SERVING while draining, then
  // no answer once the server stops accepting calls).
  EXPECT_TRUE(WaitFor(
      [&] {
        return HealthStatus(
                   grpc::CreateChannel(server.target,
                                       grpc::InsecureChannelCredentials()),
                   "") != "SERVING";
      },
      std::chrono::seconds(30)));
  const std::vector<StreamEnd> ends = ReadAllStreams(streams);
  for (int i = 0; i < kStreams; ++i) {
    EXPECT_TRUE(ends[i].status.ok())
        << "stream " << i << ": " << ends[i].status.error_code() << " "
        << ends[i].status.error_message();
    EXPECT_TRUE(ends[i].last) << "stream " << i;
  }
  const int status = WaitExit(server.pid, std::chrono::seconds(30));
  if (status == -1) {
    kill(server.pid, SIGKILL);
    waitpid(server.pid, nullptr, 0);
  }
  ASSERT_NE(status, -1) << "did not exit within 30 s of the streams' end";
  EXPECT_TRUE(WIFEXITED(status)) << "wait status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// The same streams with a grace period too short for clients that still
// read nothing: the server cancels them, which releases the workers
// blocked writing (and the queued jobs see the cancellation at once); it
// exits 0 while the streams are still unread. Each stream then ends
// CANCELLED or UNAVAILABLE, never another error.
TEST(ServerBinaryTest, SigtermWithStuckStreamsCancelsThemAndExitsZero) {
  constexpr int kStreams = 6;
  const ServerProcess server =
      StartServing({"--concurrency=2", "--queue=" + std::to_string(kStreams),
                    "--grace_period_s=0.5", "--log_level=warn"});
  ASSERT_GT(server.pid, 0);
  const auto stub = SmallWindowStub(server.target);
  std::vector<HeldStream> streams = OpenHeldStreams(server, *stub, kStreams);

  ExpectCleanExitOnSigterm(server.pid);
  const std::vector<StreamEnd> ends = ReadAllStreams(streams);
  for (int i = 0; i < kStreams; ++i) {
    EXPECT_TRUE(ends[i].status.error_code() == grpc::StatusCode::CANCELLED ||
                ends[i].status.error_code() == grpc::StatusCode::UNAVAILABLE)
        << "stream " << i << ": " << ends[i].status.error_code() << " "
        << ends[i].status.error_message();
    EXPECT_FALSE(ends[i].last) << "stream " << i;
  }
}

}  // namespace
}  // namespace fovea::server
