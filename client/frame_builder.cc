#include "client/frame_builder.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/frame/image_header.h"

namespace fovea::client {
namespace {

// A PNG colour type's channels (palette indices decode to RGB).
absl::StatusOr<int> PngChannels(int colour_type) {
  switch (colour_type) {
    case 0:
      return 1;
    case 2:
    case 3:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return absl::InvalidArgumentError(absl::StrCat(
          "compressed: PNG colour type ", colour_type, " is invalid"));
  }
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
  const std::string_view file(bytes.data(), bytes.size());
  CompressedInfo info;
  if (IsPngFile(file)) {
    FOVEA_ASSIGN_OR_RETURN(ImageFileHeader header,
                           ReadPngFileHeader(file, "compressed"));
    FOVEA_ASSIGN_OR_RETURN(info.channels, PngChannels(header.channels));
    info.format = "png";
    info.width = header.width;
    info.height = header.height;
    info.bit_depth = header.bit_depth;
    return info;
  }
  if (IsJpegFile(file)) {
    FOVEA_ASSIGN_OR_RETURN(ImageFileHeader header,
                           ReadJpegFileHeader(file, "compressed"));
    info.format = "jpeg";
    info.width = header.width;
    info.height = header.height;
    info.bit_depth = header.bit_depth;
    info.channels = header.channels;
    return info;
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
