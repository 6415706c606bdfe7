#include "client/channel.h"

#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea::client {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

MATCHER_P(IsInvalidWith, text, "") {
  return arg.status().code() == absl::StatusCode::kInvalidArgument &&
         ::testing::Value(std::string(arg.status().message()), HasSubstr(text));
}

TEST(ChannelTargetTest, OneTargetPassesUnchanged) {
  EXPECT_EQ(ChannelTarget("127.0.0.1:50051").value(), "127.0.0.1:50051");
  EXPECT_EQ(ChannelTarget("fovea:50051").value(), "fovea:50051");
  EXPECT_EQ(ChannelTarget(" dns:///fovea.default.svc:50051 ").value(),
            "dns:///fovea.default.svc:50051");
  EXPECT_EQ(ChannelTarget("ipv4:10.0.0.1:1,10.0.0.2:2").value(),
            "ipv4:10.0.0.1:1,10.0.0.2:2");
}

TEST(ChannelTargetTest, ListOfIpLiteralsBecomesOneAddressList) {
  EXPECT_EQ(ChannelTarget("127.0.0.1:5001, 127.0.0.1:5002,10.1.2.3:7").value(),
            "ipv4:127.0.0.1:5001,127.0.0.1:5002,10.1.2.3:7");
  EXPECT_EQ(ChannelTarget("[::1]:5001,[fd00::5]:5002").value(),
            "ipv6:[::1]:5001,[fd00::5]:5002");
}

TEST(ChannelTargetTest, EmptyTargetOrEntryIsNamed) {
  EXPECT_THAT(ChannelTarget(""), IsInvalidWith("server: empty target"));
  EXPECT_THAT(ChannelTarget("  "), IsInvalidWith("server: empty target"));
  EXPECT_THAT(
      ChannelTarget("127.0.0.1:1,,127.0.0.1:2"),
      IsInvalidWith("entry 2 of \"127.0.0.1:1,,127.0.0.1:2\" is empty"));
  EXPECT_THAT(ChannelTarget("127.0.0.1:1,"), IsInvalidWith("entry 2"));
}

TEST(ChannelTargetTest, HostNameInAListPointsToOneDnsName) {
  EXPECT_THAT(ChannelTarget("127.0.0.1:1,fovea-b:50051"),
              AllOf(IsInvalidWith("entry 2"), IsInvalidWith("fovea-b:50051"),
                    IsInvalidWith("not an IP address"),
                    IsInvalidWith("dns:///fovea-b:50051")));
}

TEST(ChannelTargetTest, BadEntriesAreRefused) {
  EXPECT_THAT(ChannelTarget("127.0.0.1,127.0.0.2:1"),
              IsInvalidWith("entry 1 of"));
  EXPECT_THAT(ChannelTarget("127.0.0.1:0,127.0.0.2:1"),
              IsInvalidWith("want 1..65535"));
  EXPECT_THAT(ChannelTarget("127.0.0.1:70000,127.0.0.2:1"),
              IsInvalidWith("want 1..65535"));
  EXPECT_THAT(ChannelTarget("::1:5,127.0.0.2:1"), IsInvalidWith("[IPV6]:PORT"));
  EXPECT_THAT(ChannelTarget("[::1]5,[::2]:1"), IsInvalidWith("[IPV6]:PORT"));
  EXPECT_THAT(ChannelTarget("[::1]:5,127.0.0.2:1"),
              IsInvalidWith("mixes IPv4 and IPv6"));
  EXPECT_THAT(ChannelTarget("127.0.0.1:5,127.0.0.1:5"),
              IsInvalidWith("entry 2 of \"127.0.0.1:5,127.0.0.1:5\" repeats"));
}

TEST(ClientOptionsTest, ValidateNamesTheField) {
  ClientOptions options;
  EXPECT_TRUE(Validate(options).ok());
  options.max_attempts = 0;
  EXPECT_THAT(Validate(options).message(), HasSubstr("max_attempts"));
  options.max_attempts = 6;
  EXPECT_THAT(Validate(options).message(), HasSubstr("max_attempts"));
  options.max_attempts = 1;
  options.max_message_bytes = 0;
  EXPECT_THAT(Validate(options).message(), HasSubstr("max_message_bytes"));
}

TEST(ClientOptionsTest, TlsNeedsACaForAClientCertificateAndBothHalves) {
  ClientOptions options;
  options.tls_cert_chain = "-----BEGIN CERTIFICATE-----";
  EXPECT_THAT(Validate(options).message(), HasSubstr("tls_private_key"));
  options.tls_private_key = "-----BEGIN PRIVATE KEY-----";
  EXPECT_THAT(Validate(options).message(), HasSubstr("tls_root_certs"));
  options.tls_root_certs = "-----BEGIN CERTIFICATE-----";
  EXPECT_TRUE(Validate(options).ok());
}

TEST(CreateBalancedChannelTest, RefusesWhatChannelTargetRefuses) {
  EXPECT_EQ(CreateBalancedChannel("127.0.0.1:1,", {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  ClientOptions options;
  options.max_attempts = 9;
  EXPECT_EQ(CreateBalancedChannel("127.0.0.1:1", options).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(CreateBalancedChannel("127.0.0.1:1,127.0.0.1:2", {}).ok());
}

}  // namespace
}  // namespace fovea::client
