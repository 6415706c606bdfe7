#include "client/frame_builder.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea::client {
namespace {

constexpr absl::string_view kPngSignature = "\x89PNG\r\n\x1a\n";
// Signature, IHDR length and type, width, height, bit depth, colour type.
constexpr size_t kPngHeaderBytes = 8 + 4 + 4 + 4 + 4 + 1 + 1;

uint32_t BigEndian32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) |
         (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

uint32_t BigEndian16(const unsigned char* p) {
  return (uint32_t{p[0]} << 8) | uint32_t{p[1]};
}

absl::StatusOr<CompressedInfo> ProbePng(absl::string_view bytes) {
  if (bytes.size() < kPngHeaderBytes) {
    return absl::InvalidArgumentError("PNG file truncated before its header");
  }
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  if (std::memcmp(p + 12, "IHDR", 4) != 0) {
    return absl::InvalidArgumentError("PNG file does not start with IHDR");
  }
  CompressedInfo info;
  info.format = "png";
  info.width = BigEndian32(p + 16);
  info.height = BigEndian32(p + 20);
  info.bit_depth = p[24];
  switch (p[25]) {  // PNG colour type
    case 0:
      info.channels = 1;
      break;
    case 2:
    case 3:  // palette: indices to RGB
      info.channels = 3;
      break;
    case 4:
      info.channels = 2;
      break;
    case 6:
      info.channels = 4;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("PNG colour type ", int{p[25]}, " is invalid"));
  }
  return info;
}

// Is `marker` a start-of-frame marker (SOF0-SOF15 without DHT, JPG, DAC)?
bool IsStartOfFrame(unsigned char marker) {
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
         marker != 0xCC;
}

absl::StatusOr<CompressedInfo> ProbeJpeg(absl::string_view bytes) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  size_t i = 2;  // after SOI
  while (i + 4 <= bytes.size()) {
    if (p[i] != 0xFF) {
      return absl::InvalidArgumentError(
          absl::StrCat("JPEG marker expected at byte ", i));
    }
    const unsigned char marker = p[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD9)) {
      i += 2;  // standalone marker, no length
      continue;
    }
    const uint32_t length = BigEndian16(p + i + 2);
    if (IsStartOfFrame(marker)) {
      if (i + 2 + 8 > bytes.size() || length < 8) break;
      CompressedInfo info;
      info.format = "jpeg";
      info.bit_depth = p[i + 4];
      info.height = BigEndian16(p + i + 5);
      info.width = BigEndian16(p + i + 7);
      info.channels = p[i + 9];
      return info;
    }
    i += 2 + length;
  }
  return absl::InvalidArgumentError("JPEG file has no frame header (SOF)");
}

}  // namespace

int BytesPerPixel(absl::string_view encoding) {
  if (encoding == "rgb8" || encoding == "bgr8") return 3;
  if (encoding == "16UC1") return 2;
  if (encoding == "32FC1") return 4;
  return 0;
}

absl::StatusOr<fovea::v1::Image> MakeRawImage(const void* data,
                                              size_t size_bytes, uint32_t width,
                                              uint32_t height,
                                              absl::string_view encoding,
                                              size_t step) {
  const int bytes_per_pixel = BytesPerPixel(encoding);
  if (bytes_per_pixel == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("encoding: unknown raw encoding \"", encoding,
                     "\" (expected rgb8, bgr8, 16UC1 or 32FC1)"));
  }
  if (width == 0 || height == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "width, height: must be positive, got ", width, "x", height));
  }
  const size_t row_bytes = size_t{width} * bytes_per_pixel;
  if (step == 0) step = row_bytes;
  if (step < row_bytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("step: ", step, " bytes is less than a row of ", width,
                     " ", encoding, " pixels (", row_bytes, " bytes)"));
  }
  const size_t needed = step * (height - 1) + row_bytes;
  if (size_bytes < needed) {
    return absl::InvalidArgumentError(absl::StrCat(
        "data: ", size_bytes, " bytes, need at least ", needed, " for ", width,
        "x", height, " ", encoding, " with step ", step));
  }
  if (data == nullptr) {
    return absl::InvalidArgumentError("data: null pointer");
  }
  fovea::v1::Image image;
  image.set_width(width);
  image.set_height(height);
  image.set_encoding(std::string(encoding));
  image.set_is_bigendian(false);
  image.set_step(static_cast<uint32_t>(row_bytes));
  std::string* out = image.mutable_data();
  out->resize(row_bytes * height);
  const auto* in = static_cast<const char*>(data);
  if (step == row_bytes) {
    std::memcpy(out->data(), in, row_bytes * height);
  } else {
    for (uint32_t row = 0; row < height; ++row) {
      std::memcpy(out->data() + row * row_bytes, in + row * step, row_bytes);
    }
  }
  return image;
}

absl::StatusOr<CompressedInfo> ProbeCompressedImage(absl::string_view bytes) {
  if (bytes.substr(0, kPngSignature.size()) == kPngSignature) {
    return ProbePng(bytes);
  }
  if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
      static_cast<unsigned char>(bytes[1]) == 0xD8 &&
      static_cast<unsigned char>(bytes[2]) == 0xFF) {
    return ProbeJpeg(bytes);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("compressed: ", bytes.size(),
                   " bytes that are neither a PNG nor a JPEG file"));
}

absl::StatusOr<fovea::v1::Image> MakeCompressedImage(std::string bytes) {
  FOVEA_ASSIGN_OR_RETURN(CompressedInfo info, ProbeCompressedImage(bytes));
  fovea::v1::Image image;
  image.set_width(info.width);
  image.set_height(info.height);
  *image.mutable_compressed() = std::move(bytes);
  return image;
}

absl::StatusOr<std::string> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot open ", path));
  std::string bytes((std::istreambuf_iterator<char>(in)),
                    std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrCat("cannot read ", path));
  return bytes;
}

fovea::v1::Intrinsics MakeIntrinsics(double fx, double fy, double cx,
                                     double cy) {
  fovea::v1::Intrinsics intrinsics;
  intrinsics.set_fx(fx);
  intrinsics.set_fy(fy);
  intrinsics.set_cx(cx);
  intrinsics.set_cy(cy);
  return intrinsics;
}

fovea::v1::Frame MakeFrame(fovea::v1::Image color, fovea::v1::Image depth,
                           const fovea::v1::Intrinsics& intrinsics,
                           double depth_scale) {
  fovea::v1::Frame frame;
  *frame.mutable_color() = std::move(color);
  *frame.mutable_depth() = std::move(depth);
  *frame.mutable_intrinsics() = intrinsics;
  frame.set_depth_scale(depth_scale);
  return frame;
}

}  // namespace fovea::client
