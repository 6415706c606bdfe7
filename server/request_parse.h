#ifndef FOVEA_SERVER_REQUEST_PARSE_H_
#define FOVEA_SERVER_REQUEST_PARSE_H_

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <grpcpp/support/byte_buffer.h>

#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace fovea::server {

// Parses a request's body into `message` (which it clears first). The
// service takes its requests' bytes as they came so that a body no parser
// accepts is answered here, as INVALID_ARGUMENT naming what is wrong and
// where, instead of by gRPC (whose callback API then says UNIMPLEMENTED
// with no message, before any handler could count or log the call):
//   request body is not a valid fovea.v1.DetectRequest: field
//   request_id (1) is not valid UTF-8
// On failure `message` is cleared again.
absl::Status ParseRequest(const grpc::ByteBuffer& body,
                          google::protobuf::Message* message);

// Why `bytes` are not a valid message of type `type`: the first fault a
// walk over the wire format meets (a truncated varint or length, a wire
// type that does not exist, a length past the end, a proto3 string that
// is not UTF-8), with the dotted path of the field it is in; empty when
// the walk finds none. Exposed for tests.
std::string DescribeMalformed(std::string_view bytes,
                              const google::protobuf::Descriptor& type);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_REQUEST_PARSE_H_
