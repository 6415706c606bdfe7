// libFuzzer target: DecodeFrame on hostile wire frames.
//
// The first byte picks the mode:
//   even: the rest is a serialized fovea.v1.Frame, parsed with
//         ParseFromArray and mapped as server/convert_frame.cc's ToRawFrame
//         does (reimplemented here so the target needs only fovea_frame and
//         fovea_proto, not the whole server), so PNG/JPEG decoding and the
//         wire validation run on whatever protobuf accepts;
//   odd:  the rest drives a RawFrame directly (FuzzedDataProvider): sizes
//         near and far beyond the limits, steps around width * bytes per
//         pixel, known and unknown encodings, buffers of the right and
//         wrong length, odd intrinsics, or a compressed image, so raw-buffer
//         validation is hit without going through protobuf.
// Limits are 640 x 480. A decoded frame is checked against DecodeFrame's
// contract (sizes, types, depth NaN or in (0, kMaxDepthMetres]); a breach
// aborts, which libFuzzer reports as a crash. With FOVEA_FUZZ_VERBOSE set,
// each input's outcome is printed (to see what a seed exercises).

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/frame/frame_decode.h"
#include "fovea/v1/frame.pb.h"
#include "google/protobuf/stubs/logging.h"

namespace {

constexpr fovea::FrameLimits kLimits{640, 480};
// Raw mode: sides up to this get a buffer of the exact size (so decoding
// proper runs); larger sides are only validated.
constexpr uint32_t kMaxFilledSide = 64;

void Require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz_frame_decode: contract broken: %s\n", what);
    std::abort();
  }
}

// What DecodeFrame promises on success (frame_decode.h).
void CheckDecoded(const fovea::RgbdFrame& frame) {
  Require(frame.depth.type() == CV_32FC1, "depth is CV_32FC1");
  Require(frame.color.type() == CV_8UC3, "colour is CV_8UC3");
  Require(frame.color.size() == frame.depth.size(), "colour and depth sizes");
  Require(frame.width() >= 1 && frame.height() >= 1, "non-empty frame");
  Require(static_cast<uint32_t>(frame.width()) <= kLimits.max_width &&
              static_cast<uint32_t>(frame.height()) <= kLimits.max_height,
          "frame within the limits");
  bool any_depth = false;
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* row = frame.depth.ptr<float>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      const float z = row[u];
      if (std::isnan(z)) continue;
      Require(z > 0.0f && z <= fovea::kMaxDepthMetres, "depth in range");
      any_depth = true;
    }
  }
  Require(any_depth, "at least one valid depth pixel");
}

void Decode(const fovea::RawFrame& raw) {
  absl::StatusOr<fovea::RgbdFrame> frame = fovea::DecodeFrame(raw, kLimits);
  if (std::getenv("FOVEA_FUZZ_VERBOSE") != nullptr) {
    std::fprintf(stderr, "fuzz_frame_decode: %s\n",
                 frame.ok() ? "decoded" : frame.status().ToString().c_str());
  }
  if (frame.ok()) {
    CheckDecoded(*frame);
  } else {
    Require(!frame.status().message().empty(), "errors say why");
  }
}

// As server/convert_frame.cc's ToRawImage.
fovea::RawImage ToRawImage(const fovea::v1::Image& image) {
  fovea::RawImage raw;
  raw.width = image.width();
  raw.height = image.height();
  raw.encoding = image.encoding();
  raw.is_bigendian = image.is_bigendian();
  raw.step = image.step();
  raw.data = image.data();
  raw.compressed = image.compressed();
  return raw;
}

void DecodeProto(const uint8_t* data, size_t size) {
  fovea::v1::Frame message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return;
  fovea::RawFrame raw;
  raw.color = ToRawImage(message.color());
  raw.depth = ToRawImage(message.depth());
  raw.intrinsics.fx = message.intrinsics().fx();
  raw.intrinsics.fy = message.intrinsics().fy();
  raw.intrinsics.cx = message.intrinsics().cx();
  raw.intrinsics.cy = message.intrinsics().cy();
  raw.depth_scale = message.depth_scale();
  Decode(raw);
}

// One side: usually small, sometimes at or past the limit, sometimes any.
uint32_t ConsumeSide(FuzzedDataProvider& in, uint32_t limit) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return in.ConsumeIntegralInRange<uint32_t>(0, 8);
    case 1:
      return in.ConsumeIntegralInRange<uint32_t>(0, kMaxFilledSide);
    case 2:
      return limit + in.ConsumeIntegralInRange<uint32_t>(0, 2) - 1;
    default:
      return in.ConsumeIntegral<uint32_t>();
  }
}

std::string_view ConsumeEncoding(FuzzedDataProvider& in, bool depth) {
  static constexpr std::string_view kColor[] = {"rgb8", "bgr8"};
  static constexpr std::string_view kDepth[] = {"16UC1", "32FC1"};
  static constexpr std::string_view kOther[] = {"",      "mono8", "rgba8",
                                                "16uc1", "rgb8 ", "32FC1\0"};
  const int pick = in.ConsumeIntegralInRange<int>(0, 9);
  if (pick < 2) return (depth ? kDepth : kColor)[pick];
  if (pick < 4) return (depth ? kColor : kDepth)[pick - 2];
  if (pick < 9) return kOther[pick - 4];
  return std::string_view(kOther[5].data(), 6);  // with the NUL
}

uint32_t BytesPerPixel(std::string_view encoding) {
  if (encoding == "rgb8" || encoding == "bgr8") return 3;
  if (encoding == "16UC1") return 2;
  if (encoding == "32FC1") return 4;
  return 1;
}

// Fills one image's fields; `storage` owns the bytes the views point to.
void ConsumeImage(FuzzedDataProvider& in, bool depth, fovea::RawImage& image,
                  std::string& storage) {
  image.width = ConsumeSide(in, kLimits.max_width);
  image.height = ConsumeSide(in, kLimits.max_height);
  image.encoding = ConsumeEncoding(in, depth);
  image.is_bigendian = in.ConsumeIntegralInRange<int>(0, 15) == 0;
  const uint64_t row = uint64_t{image.width} * BytesPerPixel(image.encoding);
  const int step_kind = in.ConsumeIntegralInRange<int>(0, 3);
  if (step_kind <= 1) {
    image.step = static_cast<uint32_t>(row);
  } else if (step_kind == 2) {
    image.step =
        static_cast<uint32_t>(row + in.ConsumeIntegralInRange<int64_t>(-2, 8));
  } else {
    image.step = in.ConsumeIntegral<uint32_t>();
  }
  const int data_kind = in.ConsumeIntegralInRange<int>(0, 7);
  if (data_kind == 7) {
    // A compressed image: a length-prefixed slice of the input.
    storage = in.ConsumeRandomLengthString(1 << 16);
    image.compressed = storage;
    return;
  }
  const uint64_t exact = uint64_t{image.step} * image.height;
  size_t length = 0;
  if (data_kind <= 4 && image.width <= kMaxFilledSide &&
      image.height <= kMaxFilledSide && exact <= (1u << 20)) {
    length = static_cast<size_t>(exact);
  } else {
    length = in.ConsumeIntegralInRange<size_t>(0, 4096);
  }
  // Pixels from the input, repeated to fill the buffer.
  const std::string pixels = in.ConsumeRandomLengthString(4096);
  storage.resize(length);
  for (size_t i = 0; i < length; ++i) {
    storage[i] =
        pixels.empty() ? static_cast<char>(i * 37) : pixels[i % pixels.size()];
  }
  image.data = storage;
}

double ConsumeFocal(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
    case 1:
      return 525.0;
    case 2:
      return in.ConsumeFloatingPointInRange<double>(-20.0, 2e6);
    default:
      return in.ConsumeFloatingPoint<double>();
  }
}

void DecodeRaw(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  fovea::RawFrame raw;
  std::string color_storage;
  std::string depth_storage;
  ConsumeImage(in, /*depth=*/false, raw.color, color_storage);
  ConsumeImage(in, /*depth=*/true, raw.depth, depth_storage);
  raw.intrinsics.fx = ConsumeFocal(in);
  raw.intrinsics.fy = ConsumeFocal(in);
  // An exhausted provider yields 0 / false: the plausible value then.
  raw.intrinsics.cx =
      in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : 3.5;
  raw.intrinsics.cy =
      in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : 3.5;
  raw.depth_scale = in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : 0.0;
  Decode(raw);
}

}  // namespace

// Protobuf logs every string field with invalid UTF-8 it refuses; that is
// expected here and would fill the log.
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (1u << 20)) return -1;
  if (data[0] % 2 == 0) {
    DecodeProto(data + 1, size - 1);
  } else {
    DecodeRaw(data + 1, size - 1);
  }
  return 0;
}
