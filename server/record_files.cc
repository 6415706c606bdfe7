#include "server/record_files.h"

#include <google/protobuf/util/json_util.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/frame/image_codec.h"
#include "core/frame/image_header.h"
#include "fovea/v1/frame.pb.h"
#include "server/convert.h"

namespace fovea::server {
namespace {

namespace fs = std::filesystem;

// Metres per unit of the 16-bit depth PNG a 32FC1 frame is stored as:
// 0.1 mm, up to 6.5 m.
constexpr double kFloatDepthScale = 1e-4;

// A raw image's rows as a cv::Mat header over its bytes (no copy); empty
// when its fields do not describe its data.
cv::Mat RawView(const v1::Image& image, int type, size_t pixel_bytes) {
  const size_t row = static_cast<size_t>(image.width()) * pixel_bytes;
  const size_t step = image.step() == 0 ? row : image.step();
  if (image.width() == 0 || image.height() == 0 || step < row ||
      image.data().size() < step * (image.height() - 1) + row) {
    return cv::Mat();
  }
  return cv::Mat(static_cast<int>(image.height()),
                 static_cast<int>(image.width()), type,
                 const_cast<char*>(image.data().data()), step);
}

// The colour image as a file: the compressed one as sent, a raw one as
// an RGB PNG.
absl::Status ColourFile(const v1::Image& color, const std::string& prefix,
                        RecordFiles& out) {
  if (!color.compressed().empty()) {
    const std::string& file = color.compressed();
    out.files.emplace_back(
        prefix + (IsJpegFile(file) ? "color.jpg" : "color.png"), file);
    return absl::OkStatus();
  }
  const bool rgb = color.encoding() == "rgb8";
  if (!rgb && color.encoding() != "bgr8") {
    return absl::InvalidArgumentError(
        absl::StrCat("colour encoding '", color.encoding(), "'"));
  }
  const cv::Mat view = RawView(color, CV_8UC3, 3);
  if (view.empty()) return absl::InvalidArgumentError("colour image size");
  cv::Mat bgr;  // EncodePng's order in memory
  if (rgb) {
    cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  } else {
    bgr = view;
  }
  absl::StatusOr<std::string> png = EncodePng(bgr);
  if (!png.ok()) return png.status();
  out.files.emplace_back(prefix + "color.png", *std::move(png));
  return absl::OkStatus();
}

// The depth image as a 16-bit PNG file and the scale it is in.
absl::StatusOr<double> DepthFile(const v1::Frame& frame,
                                 const std::string& prefix, RecordFiles& out) {
  const v1::Image& depth = frame.depth();
  const double scale =
      frame.depth_scale() > 0.0 ? frame.depth_scale() : kDefaultDepthScale;
  if (!depth.compressed().empty()) {
    out.files.emplace_back(prefix + "depth.png", depth.compressed());
    return scale;
  }
  if (depth.is_bigendian()) return absl::InvalidArgumentError("big-endian");
  cv::Mat units;
  double units_scale = scale;
  if (depth.encoding() == "16UC1") {
    units = RawView(depth, CV_16UC1, 2);  // the units exactly as sent
  } else if (depth.encoding() == "32FC1") {
    const cv::Mat metres = RawView(depth, CV_32FC1, 4);
    if (!metres.empty()) {
      units.create(metres.size(), CV_16UC1);
      for (int v = 0; v < metres.rows; ++v) {
        const float* in = metres.ptr<float>(v);
        uint16_t* o = units.ptr<uint16_t>(v);
        for (int u = 0; u < metres.cols; ++u) {
          o[u] = ToDepthUnits(in[u], kFloatDepthScale);
        }
      }
      units_scale = kFloatDepthScale;
    }
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("depth encoding '", depth.encoding(), "'"));
  }
  if (units.empty()) return absl::InvalidArgumentError("depth image size");
  absl::StatusOr<std::string> png = EncodePng(units);
  if (!png.ok()) return png.status();
  out.files.emplace_back(prefix + "depth.png", *std::move(png));
  return units_scale;
}

// The frame a request carries: its `frame` field when that is a Frame,
// or the Frame inside it (a TrackRequest's frame.frame); null when none.
v1::Frame* FrameIn(google::protobuf::Message* message) {
  for (int depth = 0; depth < 2 && message != nullptr; ++depth) {
    const google::protobuf::FieldDescriptor* field =
        message->GetDescriptor()->FindFieldByName("frame");
    if (field == nullptr ||
        field->type() != google::protobuf::FieldDescriptor::TYPE_MESSAGE ||
        field->is_repeated()) {
      return nullptr;
    }
    if (!message->GetReflection()->HasField(*message, field)) return nullptr;
    message = message->GetReflection()->MutableMessage(message, field);
    if (message->GetDescriptor() == v1::Frame::descriptor()) {
      return static_cast<v1::Frame*>(message);
    }
  }
  return nullptr;
}

}  // namespace

std::string ToJson(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  if (!google::protobuf::util::MessageToJsonString(message, &json, options)
           .ok()) {
    return "{}";
  }
  return json;
}

bool FrameFiles(google::protobuf::Message& request, const std::string& prefix,
                RecordFiles& out) {
  v1::Frame* frame = FrameIn(&request);
  if (frame == nullptr) return true;
  const size_t before = out.files.size();
  absl::Status colour = ColourFile(frame->color(), prefix, out);
  absl::StatusOr<double> scale = colour.ok() ? DepthFile(*frame, prefix, out)
                                             : absl::StatusOr<double>(colour);
  if (scale.ok()) {
    // The request as replay sends it: the images as the files above.
    frame->mutable_color()->Clear();
    frame->mutable_depth()->Clear();
    frame->set_depth_scale(*scale);
    return true;
  }
  out.frame_problem = std::string(scale.status().message());
  out.files.resize(before);
  frame->mutable_color()->clear_data();
  frame->mutable_color()->clear_compressed();
  frame->mutable_depth()->clear_data();
  frame->mutable_depth()->clear_compressed();
  return false;
}

std::string MetaJson(const std::string& method, int64_t sequence,
                     int64_t unix_micros, const std::string& code,
                     double seconds, const std::string& frame,
                     const std::string& more) {
  return absl::StrFormat(
      "{\"method\":\"%s\",\"sequence\":%d,\"unix_micros\":%d,\"code\":\"%s\","
      "\"seconds\":%.6f,\"frame\":\"%s\"%s}\n",
      method, sequence, unix_micros, code, seconds, frame, more);
}

bool WriteFile(const fs::path& path, const std::string& data, bool append) {
  std::ofstream out(
      path, std::ios::binary | (append ? std::ios::app : std::ios::trunc));
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  return static_cast<bool>(out);
}

}  // namespace fovea::server
