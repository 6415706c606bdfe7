#include "server/request_parse.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>
#include <grpcpp/support/proto_buffer_reader.h>

#include <cstdint>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/strings.h"

namespace fovea::server {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::internal::WireFormatLite;
using google::protobuf::io::CodedInputStream;

// Nested messages deeper than this are reported rather than walked
// (protobuf's own parser stops at 100).
constexpr int kMaxDepth = 100;

// True when `text` is well-formed UTF-8: no overlong forms, no surrogates,
// nothing past U+10FFFF (what protobuf requires of a proto3 string).
bool IsValidUtf8(std::string_view text) {
  size_t i = 0;
  while (i < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte < 0x80) {
      ++i;
      continue;
    }
    int length = 0;
    uint32_t code = 0;
    uint32_t smallest = 0;
    if ((byte & 0xe0) == 0xc0) {
      length = 2, code = byte & 0x1f, smallest = 0x80;
    } else if ((byte & 0xf0) == 0xe0) {
      length = 3, code = byte & 0x0f, smallest = 0x800;
    } else if ((byte & 0xf8) == 0xf0) {
      length = 4, code = byte & 0x07, smallest = 0x10000;
    } else {
      return false;
    }
    if (text.size() - i < static_cast<size_t>(length)) return false;
    for (int k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xc0) != 0x80) return false;
      code = (code << 6) | (next & 0x3f);
    }
    if (code < smallest || code > 0x10ffff ||
        (code >= 0xd800 && code <= 0xdfff)) {
      return false;
    }
    i += length;
  }
  return true;
}

std::string FieldPath(std::string_view parent, const FieldDescriptor* field,
                      uint32_t number) {
  std::string name = field != nullptr
                         ? absl::StrCat(field->name(), " (", number, ")")
                         : absl::StrCat("unknown field ", number);
  return parent.empty() ? name : absl::StrCat(AbslView(parent), ".", name);
}

// The first fault in `bytes` as a message of `type` (null: an unknown
// field's contents, not walked), or "".
std::string Walk(std::string_view bytes, const Descriptor* type,
                 std::string_view parent, int depth) {
  if (type == nullptr) return "";
  if (depth > kMaxDepth) {
    return absl::StrCat("messages nest deeper than ", kMaxDepth, " at ",
                        AbslView(parent));
  }
  CodedInputStream in(reinterpret_cast<const uint8_t*>(bytes.data()),
                      static_cast<int>(bytes.size()));
  while (true) {
    const uint32_t tag = in.ReadTag();
    if (tag == 0) {
      if (in.ConsumedEntireMessage() ||
          in.CurrentPosition() >= static_cast<int>(bytes.size())) {
        return "";
      }
      return absl::StrCat("a field tag at byte ", in.CurrentPosition(),
                          parent.empty() ? "" : " of ", AbslView(parent),
                          " is truncated or zero");
    }
    const uint32_t number = WireFormatLite::GetTagFieldNumber(tag);
    const FieldDescriptor* field = type->FindFieldByNumber(number);
    const std::string path = FieldPath(parent, field, number);
    switch (WireFormatLite::GetTagWireType(tag)) {
      case WireFormatLite::WIRETYPE_VARINT: {
        uint64_t value = 0;
        if (!in.ReadVarint64(&value)) {
          return absl::StrCat("field ", path, " has a truncated varint");
        }
        break;
      }
      case WireFormatLite::WIRETYPE_FIXED64: {
        uint64_t value = 0;
        if (!in.ReadLittleEndian64(&value)) {
          return absl::StrCat("field ", path, " is truncated");
        }
        break;
      }
      case WireFormatLite::WIRETYPE_FIXED32: {
        uint32_t value = 0;
        if (!in.ReadLittleEndian32(&value)) {
          return absl::StrCat("field ", path, " is truncated");
        }
        break;
      }
      case WireFormatLite::WIRETYPE_LENGTH_DELIMITED: {
        uint32_t length = 0;
        if (!in.ReadVarint32(&length)) {
          return absl::StrCat("field ", path, " has a truncated length");
        }
        const int left = static_cast<int>(bytes.size()) - in.CurrentPosition();
        if (length > static_cast<uint32_t>(left)) {
          return absl::StrCat("field ", path, " declares ", length,
                              " bytes but ", left, " follow");
        }
        const std::string_view contents =
            bytes.substr(in.CurrentPosition(), length);
        in.Skip(static_cast<int>(length));
        if (field == nullptr) break;
        if (field->type() == FieldDescriptor::TYPE_STRING &&
            field->file()->syntax() ==
                google::protobuf::FileDescriptor::SYNTAX_PROTO3 &&
            !IsValidUtf8(contents)) {
          return absl::StrCat("field ", path, " is not valid UTF-8");
        }
        if (field->type() == FieldDescriptor::TYPE_MESSAGE) {
          std::string inner =
              Walk(contents, field->message_type(), path, depth + 1);
          if (!inner.empty()) return inner;
        }
        break;
      }
      default:
        return absl::StrCat("field ", path, " has wire type ",
                            WireFormatLite::GetTagWireType(tag),
                            ", which protobuf does not use");
    }
  }
}

}  // namespace

std::string DescribeMalformed(std::string_view bytes, const Descriptor& type) {
  return Walk(bytes, &type, "", 0);
}

absl::Status ParseRequest(const grpc::ByteBuffer& body,
                          google::protobuf::Message* message) {
  message->Clear();
  // A copy of a ByteBuffer shares its slices; ProtoBufferReader reads them
  // in place, as gRPC's own deserialisation does.
  grpc::ByteBuffer reader_buffer(body);
  grpc::ProtoBufferReader reader(&reader_buffer);
  if (message->ParseFromZeroCopyStream(&reader)) return absl::OkStatus();
  message->Clear();
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (body.Dump(&slices).ok()) {
    for (const grpc::Slice& slice : slices) {
      bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
    }
  }
  std::string why = DescribeMalformed(bytes, *message->GetDescriptor());
  if (why.empty()) why = "protobuf could not parse it";
  return absl::InvalidArgumentError(
      absl::StrCat("request body is not a valid ",
                   message->GetDescriptor()->full_name(), ": ", why));
}

}  // namespace fovea::server
