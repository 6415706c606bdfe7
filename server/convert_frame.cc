// Frames: the wire's v1::Frame to core's RawFrame and back (convert.h).
#include <cmath>
#include <cstdint>
#include <string>

#include "server/convert.h"

namespace fovea::server {
namespace {

RawImage ToRawImage(const v1::Image& image) {
  RawImage raw;
  raw.width = image.width();
  raw.height = image.height();
  raw.encoding = image.encoding();
  raw.is_bigendian = image.is_bigendian();
  raw.step = image.step();
  raw.data = image.data();
  raw.compressed = image.compressed();
  return raw;
}

}  // namespace

uint16_t ToDepthUnits(float metres, double metres_per_unit) {
  const double units = std::round(metres / metres_per_unit);
  // NaN fails both comparisons; a rounded value above 0 is at least 1.
  return units > 0.0 && units <= 65535.0 ? static_cast<uint16_t>(units) : 0;
}

RawFrame ToRawFrame(const v1::Frame& frame) {
  RawFrame raw;
  raw.color = ToRawImage(frame.color());
  raw.depth = ToRawImage(frame.depth());
  raw.intrinsics.fx = frame.intrinsics().fx();
  raw.intrinsics.fy = frame.intrinsics().fy();
  raw.intrinsics.cx = frame.intrinsics().cx();
  raw.intrinsics.cy = frame.intrinsics().cy();
  raw.depth_scale = frame.depth_scale();
  return raw;
}

v1::Frame ToProtoFrame(const RgbdFrame& frame, DepthEncoding depth_encoding,
                       double depth_scale) {
  v1::Frame out;
  const int width = frame.color.cols;
  const int height = frame.color.rows;

  v1::Image* color = out.mutable_color();
  color->set_width(width);
  color->set_height(height);
  color->set_encoding("rgb8");
  color->set_step(width * 3);
  std::string* color_bytes = color->mutable_data();
  color_bytes->reserve(static_cast<size_t>(width) * height * 3);
  for (int v = 0; v < height; ++v) {
    color_bytes->append(reinterpret_cast<const char*>(frame.color.ptr(v)),
                        static_cast<size_t>(width) * 3);
  }

  v1::Image* depth = out.mutable_depth();
  depth->set_width(frame.depth.cols);
  depth->set_height(frame.depth.rows);
  std::string* depth_bytes = depth->mutable_data();
  if (depth_encoding == DepthEncoding::k32FC1) {
    depth->set_encoding("32FC1");
    depth->set_step(frame.depth.cols * 4);
    for (int v = 0; v < frame.depth.rows; ++v) {
      depth_bytes->append(reinterpret_cast<const char*>(frame.depth.ptr(v)),
                          static_cast<size_t>(frame.depth.cols) * 4);
    }
  } else {
    depth->set_encoding("16UC1");
    depth->set_step(frame.depth.cols * 2);
    out.set_depth_scale(depth_scale);
    depth_bytes->resize(static_cast<size_t>(frame.depth.cols) *
                        frame.depth.rows * 2);
    char* dst = depth_bytes->data();
    for (int v = 0; v < frame.depth.rows; ++v) {
      const float* row = frame.depth.ptr<float>(v);
      for (int u = 0; u < frame.depth.cols; ++u) {
        const uint16_t value = ToDepthUnits(row[u], depth_scale);
        // Little-endian, as the wire says.
        *dst++ = static_cast<char>(value & 0xff);
        *dst++ = static_cast<char>(value >> 8);
      }
    }
  }

  out.mutable_intrinsics()->set_fx(frame.intrinsics.fx);
  out.mutable_intrinsics()->set_fy(frame.intrinsics.fy);
  out.mutable_intrinsics()->set_cx(frame.intrinsics.cx);
  out.mutable_intrinsics()->set_cy(frame.intrinsics.cy);
  return out;
}

}  // namespace fovea::server
