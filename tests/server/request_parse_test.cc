#include "server/request_parse.h"

#include <gmock/gmock.h>
#include <grpcpp/support/byte_buffer.h>
#include <gtest/gtest.h>

#include <string>

#include "fovea/v1/detect.pb.h"

namespace fovea::server {
namespace {

using ::testing::HasSubstr;

grpc::ByteBuffer Body(const std::string& bytes) {
  grpc::Slice slice(bytes);
  return grpc::ByteBuffer(&slice, 1);
}

// A DetectRequest whose request_id holds `text`, serialised as is.
std::string WithRequestId(const std::string& text) {
  v1::DetectRequest request;
  request.set_request_id(text);
  request.mutable_frame()->set_frame_id("camera");
  return request.SerializePartialAsString();
}

// The walk and protobuf agree on what UTF-8 is: each text parses exactly
// when the walk finds no fault, and a fault names the field.
TEST(ParseRequest, AgreesWithProtobufOnUtf8) {
  struct Case {
    const char* name;
    std::string text;
    bool valid;
  };
  const Case cases[] = {
      {"ascii", "r1", true},
      {"two bytes", "h\xc3\xa9llo", true},
      {"four bytes", "\xf0\x9f\x98\x80", true},
      {"lone continuation", "\x80", false},
      {"overlong slash", "\xc0\xaf", false},
      {"surrogate", "\xed\xa0\x80", false},
      {"past U+10FFFF", "\xf4\x90\x80\x80", false},
      {"cut short", "\xe2\x82", false},
  };
  for (const Case& c : cases) {
    const std::string bytes = WithRequestId(c.text);
    v1::DetectRequest parsed;
    EXPECT_EQ(parsed.ParseFromString(bytes), c.valid) << c.name;
    const std::string why =
        DescribeMalformed(bytes, *v1::DetectRequest::descriptor());
    EXPECT_EQ(why.empty(), c.valid) << c.name << ": " << why;
    const absl::Status status = ParseRequest(Body(bytes), &parsed);
    EXPECT_EQ(status.ok(), c.valid) << c.name;
    if (!c.valid) {
      EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
      EXPECT_THAT(status.message(),
                  HasSubstr("field request_id (1) is not valid UTF-8"));
      EXPECT_EQ(parsed.ByteSizeLong(), 0u) << "cleared on failure";
    } else {
      EXPECT_EQ(parsed.request_id(), c.text);
      EXPECT_EQ(parsed.frame().frame_id(), "camera");
    }
  }
}

// A body split over several slices parses like one.
TEST(ParseRequest, ReadsEverySlice) {
  v1::DetectRequest request;
  request.set_request_id("split");
  request.mutable_frame()->mutable_color()->set_data(std::string(5000, 'x'));
  const std::string bytes = request.SerializeAsString();
  grpc::Slice slices[] = {grpc::Slice(bytes.substr(0, 7)),
                          grpc::Slice(bytes.substr(7, 3000)),
                          grpc::Slice(bytes.substr(3007))};
  v1::DetectRequest parsed;
  ASSERT_TRUE(ParseRequest(grpc::ByteBuffer(slices, 3), &parsed).ok());
  EXPECT_EQ(parsed.request_id(), "split");
  EXPECT_EQ(parsed.frame().color().data().size(), 5000u);
}

// Faults outside strings: each is named with its field's path.
TEST(DescribeMalformed, NamesTheFieldOfEachFault) {
  const auto& type = *v1::DetectRequest::descriptor();
  EXPECT_EQ(DescribeMalformed(std::string("\x08\xff\xff", 3), type),
            "field request_id (1) has a truncated varint");
  EXPECT_EQ(DescribeMalformed(std::string("\x12\x03\x0a", 3), type),
            "field frame (2) declares 3 bytes but 1 follow");
  // Field 99 is not in DetectRequest; its contents are not walked.
  EXPECT_EQ(DescribeMalformed(std::string("\x9a\x06\x01\xff", 4), type), "");
  EXPECT_THAT(DescribeMalformed(std::string("\x9d\x06\x01", 3), type),
              HasSubstr("unknown field 99 is truncated"));
  EXPECT_EQ(DescribeMalformed("", type), "");
}

}  // namespace
}  // namespace fovea::server
