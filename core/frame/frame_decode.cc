#include "core/frame/frame_decode.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/frame/image_codec.h"
#include "core/frame/image_header.h"

namespace fovea {
namespace {

// Largest FrameLimits.max_width / max_height accepted: keeps every byte
// count of a 4-byte-per-pixel row and image inside an int for cv::Mat.
constexpr uint32_t kLargestLimit = 1u << 15;
// Longest prefix of a client-supplied encoding quoted in an error.
constexpr size_t kQuotedEncodingChars = 32;

constexpr int kPngColorTypeGrey = 0;

enum class Slot { kColor, kDepth };

// How an image's pixels are carried.
enum class Format { kRgb8, kBgr8, kDepth16, kDepth32F, kPng, kJpeg };

struct Encoding {
  absl::string_view name;
  Format format;
  Slot slot;
  uint32_t bytes_per_pixel;
};

constexpr std::array<Encoding, 4> kEncodings = {{
    {"rgb8", Format::kRgb8, Slot::kColor, 3},
    {"bgr8", Format::kBgr8, Slot::kColor, 3},
    {"16UC1", Format::kDepth16, Slot::kDepth, 2},
    {"32FC1", Format::kDepth32F, Slot::kDepth, 4},
}};

// What Inspect learnt about an image without touching its pixels.
struct Layout {
  Format format = Format::kRgb8;
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t step = 0;  // bytes per row; raw formats only
};

absl::string_view SlotName(Slot slot) {
  return slot == Slot::kColor ? "colour" : "depth";
}

absl::string_view SlotEncodings(Slot slot) {
  return slot == Slot::kColor ? "rgb8 or bgr8" : "16UC1 or 32FC1";
}

std::string Quoted(absl::string_view text) {
  std::string quoted = absl::StrCat(
      "\"", absl::CHexEscape(text.substr(0, kQuotedEncodingChars)), "\"");
  if (text.size() > kQuotedEncodingChars) quoted += "...";
  return quoted;
}

// Looks up a non-empty encoding and checks it belongs in `slot`.
absl::StatusOr<const Encoding*> FindEncoding(absl::string_view name, Slot slot,
                                             absl::string_view field) {
  for (const Encoding& encoding : kEncodings) {
    if (encoding.name != name) continue;
    if (encoding.slot != slot) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".encoding: ", Quoted(name), " is a ", SlotName(encoding.slot),
          " encoding; ", SlotName(slot), " takes ", SlotEncodings(slot)));
    }
    return &encoding;
  }
  return absl::InvalidArgumentError(
      absl::StrCat(field, ".encoding: unknown encoding ", Quoted(name), "; ",
                   SlotName(slot), " takes ", SlotEncodings(slot)));
}

// `origin` says where the numbers come from, e.g. " (PNG header)".
absl::Status CheckDimensions(uint64_t width, uint64_t height,
                             absl::string_view field, absl::string_view origin,
                             const FrameLimits& limits) {
  if (width == 0 || height == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".", width == 0 ? "width" : "height", ": ", width,
                     " x ", height, origin, " is empty"));
  }
  if (width > limits.max_width) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".width: ", width, origin, " exceeds the limit of ",
                     limits.max_width, " pixels"));
  }
  if (height > limits.max_height) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".height: ", height, origin,
                     " exceeds the limit of ", limits.max_height, " pixels"));
  }
  return absl::OkStatus();
}

// Checks that width, height, step and encoding sent alongside a compressed
// file agree with it. Compressed depth is always 16UC1.
absl::Status CheckAgreesWithFile(const RawImage& image,
                                 const ImageFileHeader& file,
                                 absl::string_view kind, Slot slot,
                                 absl::string_view field) {
  if (image.width != 0 && image.width != file.width) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".width: ", image.width, " does not match the ",
                     kind, "'s width ", file.width));
  }
  if (image.height != 0 && image.height != file.height) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".height: ", image.height, " does not match the ",
                     kind, "'s height ", file.height));
  }
  uint32_t bytes_per_pixel = slot == Slot::kColor ? 3 : 2;
  if (!image.encoding.empty()) {
    absl::StatusOr<const Encoding*> encoding =
        FindEncoding(AbslView(image.encoding), slot, field);
    if (!encoding.ok()) return encoding.status();
    if (slot == Slot::kDepth && (*encoding)->format != Format::kDepth16) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".encoding: ", Quoted(AbslView(image.encoding)),
                       " does not match the 16-bit ", kind, " (16UC1)"));
    }
    bytes_per_pixel = (*encoding)->bytes_per_pixel;
  }
  const uint64_t row_bytes = uint64_t{file.width} * bytes_per_pixel;
  if (image.step != 0 && image.step != row_bytes) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".step: ", image.step, " does not match the ", kind,
                     "'s rows of ", file.width, " * ", bytes_per_pixel, " = ",
                     row_bytes, " bytes"));
  }
  return absl::OkStatus();
}

absl::StatusOr<Layout> InspectCompressed(const RawImage& image, Slot slot,
                                         absl::string_view field,
                                         const FrameLimits& limits) {
  const absl::string_view file = AbslView(image.compressed);
  Layout layout;
  ImageFileHeader header;
  absl::string_view kind;
  if (IsPngFile(image.compressed)) {
    kind = "PNG";
    FOVEA_ASSIGN_OR_RETURN(
        ImageFileHeader png,
        ReadPngFileHeader(image.compressed,
                          absl::StrCat(field, ".compressed")));
    header = png;
    layout.format = Format::kPng;
    if (slot == Slot::kDepth &&
        (header.bit_depth != 16 || header.channels != kPngColorTypeGrey)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".compressed: a ", header.bit_depth,
                       "-bit PNG of colour type ", header.channels,
                       "; depth takes a 16-bit grey PNG (colour type 0)"));
    }
    if (slot == Slot::kColor && header.bit_depth > 8) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".compressed: a ", header.bit_depth,
          "-bit PNG; colour takes an 8-bit PNG (16-bit grey is for depth)"));
    }
  } else if (IsJpegFile(image.compressed)) {
    kind = "JPEG";
    if (slot == Slot::kDepth) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".compressed: a JPEG; depth takes a 16-bit grey PNG"));
    }
    FOVEA_ASSIGN_OR_RETURN(
        ImageFileHeader jpeg,
        ReadJpegFileHeader(image.compressed,
                           absl::StrCat(field, ".compressed")));
    header = jpeg;
    layout.format = Format::kJpeg;
  } else {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".compressed: not a decodable ",
        slot == Slot::kColor ? "PNG or JPEG" : "PNG", " (", file.size(),
        " bytes starting ", Quoted(file.substr(0, 8)), ")"));
  }
  absl::Status status =
      CheckDimensions(header.width, header.height, field,
                      absl::StrCat(" (", kind, " header)"), limits);
  if (!status.ok()) return status;
  status = CheckAgreesWithFile(image, header, kind, slot, field);
  if (!status.ok()) return status;
  layout.width = header.width;
  layout.height = header.height;
  return layout;
}

absl::StatusOr<Layout> InspectRaw(const RawImage& image, Slot slot,
                                  absl::string_view field,
                                  const FrameLimits& limits) {
  if (image.encoding.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".encoding: empty; raw ", SlotName(slot),
                     " data takes ", SlotEncodings(slot)));
  }
  absl::StatusOr<const Encoding*> encoding =
      FindEncoding(AbslView(image.encoding), slot, field);
  if (!encoding.ok()) return encoding.status();
  absl::Status status =
      CheckDimensions(image.width, image.height, field, "", limits);
  if (!status.ok()) return status;
  const uint64_t bytes_per_pixel = (*encoding)->bytes_per_pixel;
  const uint64_t row_bytes = uint64_t{image.width} * bytes_per_pixel;
  if (image.step < row_bytes) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".step: ", image.step, " is less than width * ",
                     bytes_per_pixel, " = ", row_bytes));
  }
  const uint64_t needed = uint64_t{image.step} * (image.height - 1) + row_bytes;
  if (image.data.size() < needed) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".data: ", image.data.size(), " bytes, fewer than the ", needed,
        " that ", image.height, " rows of step ", image.step, " need"));
  }
  Layout layout;
  layout.format = (*encoding)->format;
  layout.width = image.width;
  layout.height = image.height;
  layout.step = image.step;
  return layout;
}

// Checks one image of the frame without allocating anything.
absl::StatusOr<Layout> Inspect(const RawImage& image, Slot slot,
                               absl::string_view field,
                               const FrameLimits& limits) {
  if (image.is_bigendian) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".is_bigendian: true, but only little-endian data is taken"));
  }
  if (!image.data.empty() && !image.compressed.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".data: ", image.data.size(), " bytes set together with ", field,
        ".compressed (", image.compressed.size(), " bytes); send one of them"));
  }
  if (!image.compressed.empty()) {
    return InspectCompressed(image, slot, field, limits);
  }
  if (image.data.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".data: empty, and no ", field, ".compressed either"));
  }
  return InspectRaw(image, slot, field, limits);
}

// Decodes a compressed file already inspected into `layout`: the codec
// checks the file's header against the layout's size before allocating.
absl::StatusOr<cv::Mat> DecodeFile(std::string_view file, const Layout& layout,
                                   ImageDecodeMode mode,
                                   absl::string_view field,
                                   const InterruptCheck& interrupt) {
  ImageDecodeOptions options;
  options.mode = mode;
  options.interrupt = interrupt;
  options.max_width = layout.width;
  options.max_height = layout.height;
  return DecodeImage(file, options, absl::StrCat(field, ".compressed"));
}

float DepthFromMetres(float metres) {
  return metres > 0.0f && metres <= kMaxDepthMetres
             ? metres
             : std::numeric_limits<float>::quiet_NaN();
}

float DepthFromUnits(uint32_t units, double scale) {
  return units == 0 ? std::numeric_limits<float>::quiet_NaN()
                    : DepthFromMetres(static_cast<float>(units * scale));
}

cv::Mat ColorFromRaw(const RawImage& image, const Layout& layout) {
  cv::Mat color(static_cast<int>(layout.height), static_cast<int>(layout.width),
                CV_8UC3);
  const size_t row_bytes = size_t{layout.width} * 3;
  for (int v = 0; v < color.rows; ++v) {
    const auto* src = reinterpret_cast<const unsigned char*>(
        image.data.data() + size_t{layout.step} * v);
    unsigned char* dst = color.ptr<unsigned char>(v);
    if (layout.format == Format::kRgb8) {
      std::memcpy(dst, src, row_bytes);
      continue;
    }
    for (size_t i = 0; i < row_bytes; i += 3) {
      dst[i] = src[i + 2];
      dst[i + 1] = src[i + 1];
      dst[i + 2] = src[i];
    }
  }
  return color;
}

cv::Mat DepthFromRaw(const RawImage& image, const Layout& layout,
                     double scale) {
  cv::Mat depth(static_cast<int>(layout.height), static_cast<int>(layout.width),
                CV_32FC1);
  const int width = depth.cols;
  for (int v = 0; v < depth.rows; ++v) {
    const auto* src = reinterpret_cast<const unsigned char*>(
        image.data.data() + size_t{layout.step} * v);
    float* dst = depth.ptr<float>(v);
    if (layout.format == Format::kDepth16) {
      for (int u = 0; u < width; ++u) {
        const uint32_t units =
            uint32_t{src[2 * u]} | (uint32_t{src[2 * u + 1]} << 8);
        dst[u] = DepthFromUnits(units, scale);
      }
    } else {
      FOVEA_CHECK(layout.format == Format::kDepth32F);
      for (int u = 0; u < width; ++u) {
        const uint32_t bits =
            uint32_t{src[4 * u]} | (uint32_t{src[4 * u + 1]} << 8) |
            (uint32_t{src[4 * u + 2]} << 16) | (uint32_t{src[4 * u + 3]} << 24);
        dst[u] = DepthFromMetres(std::bit_cast<float>(bits));
      }
    }
  }
  return depth;
}

absl::StatusOr<cv::Mat> DecodeColor(const RawImage& image, const Layout& layout,
                                    absl::string_view field,
                                    const InterruptCheck& interrupt) {
  if (layout.format == Format::kRgb8 || layout.format == Format::kBgr8) {
    return ColorFromRaw(image, layout);
  }
  const absl::string_view kind = layout.format == Format::kPng ? "PNG" : "JPEG";
  FOVEA_ASSIGN_OR_RETURN(cv::Mat decoded,
                         DecodeFile(image.compressed, layout,
                                    ImageDecodeMode::kColor, field, interrupt));
  const cv::Mat& bgr = decoded;
  if (bgr.type() != CV_8UC3 || bgr.cols != static_cast<int>(layout.width) ||
      bgr.rows != static_cast<int>(layout.height)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".compressed: not a decodable ", kind, " (",
                     image.compressed.size(), " bytes)"));
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

absl::StatusOr<cv::Mat> DecodeDepth(const RawImage& image, const Layout& layout,
                                    double scale, absl::string_view field,
                                    const InterruptCheck& interrupt) {
  if (layout.format != Format::kPng) return DepthFromRaw(image, layout, scale);
  FOVEA_ASSIGN_OR_RETURN(cv::Mat decoded, DecodeFile(image.compressed, layout,
                                                     ImageDecodeMode::kAnyDepth,
                                                     field, interrupt));
  const cv::Mat& units = decoded;
  if (units.type() != CV_16UC1 ||
      units.cols != static_cast<int>(layout.width) ||
      units.rows != static_cast<int>(layout.height)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".compressed: not a decodable PNG (",
                     image.compressed.size(), " bytes)"));
  }
  cv::Mat depth(units.rows, units.cols, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    const uint16_t* src = units.ptr<uint16_t>(v);
    float* dst = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) dst[u] = DepthFromUnits(src[u], scale);
  }
  return depth;
}

bool HasValidDepth(const cv::Mat& depth) {
  for (int v = 0; v < depth.rows; ++v) {
    const float* row = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!std::isnan(row[u])) return true;
    }
  }
  return false;
}

}  // namespace

absl::Status Validate(const FrameLimits& limits) {
  if (limits.max_width == 0 || limits.max_width > kLargestLimit) {
    return absl::InvalidArgumentError(
        absl::StrCat("limits.max_width: ", limits.max_width, " is not in [1, ",
                     kLargestLimit, "]"));
  }
  if (limits.max_height == 0 || limits.max_height > kLargestLimit) {
    return absl::InvalidArgumentError(
        absl::StrCat("limits.max_height: ", limits.max_height,
                     " is not in [1, ", kLargestLimit, "]"));
  }
  return absl::OkStatus();
}

absl::Status ValidateIntrinsics(const Intrinsics& intrinsics,
                                std::string_view field_name) {
  const absl::string_view field = AbslView(field_name);
  const struct {
    absl::string_view name;
    double value;
    bool positive;
  } kParameters[] = {{"fx", intrinsics.fx, true},
                     {"fy", intrinsics.fy, true},
                     {"cx", intrinsics.cx, false},
                     {"cy", intrinsics.cy, false}};
  for (const auto& parameter : kParameters) {
    if (!std::isfinite(parameter.value)) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".", parameter.name, ": ", parameter.value, " is not finite"));
    }
    if (parameter.positive && parameter.value <= 0.0) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".", parameter.name, ": ", parameter.value,
                       " must be > 0 (a focal length in pixels)"));
    }
    if (parameter.positive && (parameter.value < kMinFocalPixels ||
                               parameter.value > kMaxFocalPixels)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".", parameter.name, ": ", parameter.value,
                       " is not a plausible focal length; expected [",
                       kMinFocalPixels, ", ", kMaxFocalPixels, "] pixels"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<RgbdFrame> DecodeFrame(const RawFrame& raw,
                                      const FrameLimits& limits,
                                      const InterruptCheck& interrupt) {
  absl::Status status = Validate(limits);
  if (!status.ok()) return status;
  status = ValidateIntrinsics(raw.intrinsics, "frame.intrinsics");
  if (!status.ok()) return status;
  if (!std::isfinite(raw.depth_scale) || raw.depth_scale < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame.depth_scale: ", raw.depth_scale,
                     " must be finite and > 0 (or 0 for the default ",
                     kDefaultDepthScale, ")"));
  }
  const double scale =
      raw.depth_scale == 0.0 ? kDefaultDepthScale : raw.depth_scale;

  FOVEA_ASSIGN_OR_RETURN(Layout color_layout, Inspect(raw.color, Slot::kColor,
                                                      "frame.color", limits));
  FOVEA_ASSIGN_OR_RETURN(Layout depth_layout, Inspect(raw.depth, Slot::kDepth,
                                                      "frame.depth", limits));
  if (color_layout.width != depth_layout.width ||
      color_layout.height != depth_layout.height) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame.depth: ", depth_layout.width, " x ",
                     depth_layout.height, " does not match frame.color ",
                     color_layout.width, " x ", color_layout.height));
  }

  // A crop can put the principal point outside the image, but the image's
  // centre cannot lie more than 10 focal lengths from it (84 degrees off
  // the optical axis): that is a unit error or garbage.
  const struct {
    absl::string_view name;
    double value;
    uint32_t size;
    double focal;
  } kCentre[] = {
      {"cx", raw.intrinsics.cx, color_layout.width, raw.intrinsics.fx},
      {"cy", raw.intrinsics.cy, color_layout.height, raw.intrinsics.fy}};
  for (const auto& c : kCentre) {
    const double lo = 0.5 * c.size - 10.0 * c.focal;
    const double hi = 0.5 * c.size + 10.0 * c.focal;
    if (c.value < lo || c.value > hi) {
      return absl::InvalidArgumentError(absl::StrCat(
          "frame.intrinsics.", c.name, ": ", c.value,
          " puts the image more than 10 focal lengths off the optical axis; "
          "expected [",
          lo, ", ", hi, "] pixels"));
    }
  }

  RgbdFrame frame;
  frame.intrinsics = raw.intrinsics;
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat depth,
      DecodeDepth(raw.depth, depth_layout, scale, "frame.depth", interrupt));
  if (!HasValidDepth(depth)) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame.depth: no valid depth pixel in ", depth.cols, " x ",
                     depth.rows, " (all 0, NaN, negative or inf)"));
  }
  frame.depth = std::move(depth);
  FOVEA_ASSIGN_OR_RETURN(cv::Mat color, DecodeColor(raw.color, color_layout,
                                                    "frame.color", interrupt));
  frame.color = std::move(color);
  return frame;
}

}  // namespace fovea
