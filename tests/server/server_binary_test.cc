// The fovea-server executable: --help, bad flags, flags from the
// environment, missing models, reflection, mutual TLS and a flood of
// silent connections. Its exit on SIGTERM is in
// server_binary_shutdown_test.cc; starting and stopping the process, in
// server_process.h.

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fovea/v1/perception.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/server_process.h"
#include "tests/server/test_util.h"

namespace fovea::server {
namespace {

using ::fovea::server::testing::ExpectCleanExitOnSigterm;
using ::fovea::server::testing::HttpGet;
using ::fovea::server::testing::MakeSyntheticRequest;
using ::fovea::server::testing::MetricValue;
using ::fovea::server::testing::ServerProcess;
using ::fovea::server::testing::StartServing;
using ::fovea::server::testing::StartUntil;
using ::fovea::server::testing::WaitFor;
using ::testing::HasSubstr;

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
  // is served even with the flood's sockets still open on this side. (Each
  // try may take 15 s: a TSan build on a loaded machine took 2.5 s for this
  // Detect, and later 4-5.4 s, when 5 s tries all failed.)
  EXPECT_TRUE(
      WaitFor([&] { return DetectOk(server.target, std::chrono::seconds(15)); },
              std::chrono::seconds(60)));
  for (const int fd : flood) close(fd);
  EXPECT_TRUE(DetectOk(server.target, std::chrono::seconds(15)));
  ExpectCleanExitOnSigterm(server.pid);
}

// The reflection service's one method: `request` (serialized; none when
// empty) sent, the first answer read into `answer` (when one came), the
// stream half-closed; its status.
grpc::StatusCode ReflectionExchange(const std::string& target,
                                    const std::string& request,
                                    std::string* answer) {
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
  grpc::ByteBuffer in;
  bool read = false;
  if (!request.empty()) {
    grpc::Slice slice(request);
    grpc::ByteBuffer out(&slice, 1);
    call->Write(out, reinterpret_cast<void*>(2));
    queue.Next(&tag, &ok);
    call->Read(&in, reinterpret_cast<void*>(3));
    queue.Next(&tag, &ok);
    read = ok;
  }
  call->WritesDone(reinterpret_cast<void*>(4));
  queue.Next(&tag, &ok);
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(5));
  queue.Next(&tag, &ok);
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  std::vector<grpc::Slice> slices;
  if (read && answer != nullptr && in.Dump(&slices).ok()) {
    for (const grpc::Slice& slice : slices) {
      answer->append(reinterpret_cast<const char*>(slice.begin()),
                     slice.size());
    }
  }
  return status.error_code();
}

grpc::StatusCode ReflectionCallStatus(const std::string& target) {
  return ReflectionExchange(target, "", nullptr);
}

// Reflection's answer to file_containing_symbol `symbol` (a request
// written by hand: grpc++ ships no reflection client): true when it holds a
// file descriptor, false when it holds an error (or nothing came).
bool ReflectionKnows(const std::string& target, const std::string& symbol) {
  // ServerReflectionRequest{file_containing_symbol (field 4) = symbol}.
  std::string request = "\x22";
  request += static_cast<char>(symbol.size());
  request += symbol;
  std::string bytes;
  ReflectionExchange(target, request, &bytes);
  // The response's top-level fields are all length-delimited: walk them
  // to the oneof, file_descriptor_response (4) or error_response (7).
  size_t at = 0;
  while (at < bytes.size()) {
    const int field = static_cast<uint8_t>(bytes[at]) >> 3;
    ++at;
    uint64_t length = 0;
    for (int shift = 0; at < bytes.size(); shift += 7) {
      const uint8_t b = static_cast<uint8_t>(bytes[at++]);
      length |= static_cast<uint64_t>(b & 0x7f) << shift;
      if ((b & 0x80) == 0) break;
    }
    if (field == 4) return true;
    if (field == 7) return false;
    at += length;
  }
  return false;
}

// Every service reflection lists can be called through it: the contract's
// and grpc.health.v1 (whose descriptor gRPC's own health service lacks).
TEST(ServerBinaryTest, ReflectionDescribesEveryServiceItLists) {
  const ServerProcess server = StartServing({"--concurrency=1"});
  ASSERT_GT(server.pid, 0);
  EXPECT_TRUE(ReflectionKnows(server.target, "fovea.v1.Perception"));
  EXPECT_TRUE(ReflectionKnows(server.target, "grpc.health.v1.Health"));
  EXPECT_FALSE(ReflectionKnows(server.target, "no.such.Service"));
  ExpectCleanExitOnSigterm(server.pid);
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
  grpc::SslCredentialsOptions with_cert;
  with_cert.pem_root_certs = ReadAll(dir + "/ca.pem");
  with_cert.pem_cert_chain = ReadAll(dir + "/client.pem");
  with_cert.pem_private_key = ReadAll(dir + "/client.key");
  grpc::SslCredentialsOptions without_cert;
  without_cert.pem_root_certs = with_cert.pem_root_certs;
  const ServerProcess server = StartUntil(
      {"--metrics_listen=", "--concurrency=1",
       "--tls_cert=" + dir + "/server.pem", "--tls_key=" + dir + "/server.key",
       "--tls_client_ca=" + dir + "/ca.pem"},
      [&](const std::string& target) {
        return DetectWith(target, grpc::SslCredentials(with_cert)) ==
               grpc::StatusCode::OK;
      });
  ASSERT_GT(server.pid, 0) << "the mutual-TLS server never served a client "
                              "with a certificate";
  const std::string& target = server.target;
  EXPECT_NE(DetectWith(target, grpc::SslCredentials(without_cert)),
            grpc::StatusCode::OK);
  EXPECT_NE(DetectWith(target, grpc::InsecureChannelCredentials()),
            grpc::StatusCode::OK);
  ExpectCleanExitOnSigterm(server.pid);
  std::filesystem::remove_all(dir);
}

TEST(ServerBinaryTest, BadTlsFlagsStopStartUpNamingThem) {
  const auto [output, status] = RunToCompletion("--tls_cert=/nonexistent.pem");
  EXPECT_NE(status, 0);
  EXPECT_THAT(output, HasSubstr("--tls_cert"));
}

}  // namespace
}  // namespace fovea::server
