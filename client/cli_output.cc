#include "client/cli_output.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/option_names.h"
#include "client/rle.h"
#include "core/base/status_macros.h"
#include "core/frame/image_codec.h"
#include "google/protobuf/util/json_util.h"
#include "proto/enum_names.h"

namespace fovea::client {
namespace {

// An enum value's name without its enum's prefix, in lower case
// (proto/enum_names.h): "simple" for PYRAMID_SIMPLE.
std::string ShortName(const google::protobuf::EnumDescriptor* type, int value) {
  const google::protobuf::EnumValueDescriptor* found =
      type->FindValueByNumber(value);
  return found != nullptr ? fovea::v1::ShortEnumName(*found)
                          : std::to_string(value);
}

using PointList = google::protobuf::RepeatedPtrField<fovea::v1::AttentionPoint>;

constexpr double kOverlayAlpha = 0.5;  // weight of the map / mask tint
// Circle radius of the rank-0 point: this fraction of the image's smaller
// side, at least kMinRadiusPx; the last point's is kLastRadiusFraction of
// that.
constexpr double kFirstRadiusFraction = 1.0 / 20.0;
constexpr int kMinRadiusPx = 6;
constexpr double kLastRadiusFraction = 0.4;
constexpr double kGoldenRatioConjugate = 0.618033988749895;

absl::Status WriteText(const std::filesystem::path& path,
                       const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out)
    return absl::InternalError(absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

absl::Status WritePng(const std::filesystem::path& path, const cv::Mat& image) {
  absl::StatusOr<std::string> png = EncodePng(image);
  if (!png.ok()) {
    return absl::InternalError(absl::StrCat("cannot write ", path.string(),
                                            ": ", png.status().message()));
  }
  return WriteText(path, *png);
}

// A saliency map image (16-bit grey PNG, value / 65535 in [0, 1]; or raw
// 16UC1 / 32FC1 / mono8) as CV_32F in [0, 1].
absl::StatusOr<cv::Mat> DecodeMap(const fovea::v1::Image& image) {
  cv::Mat decoded;
  try {
    if (!image.compressed().empty()) {
      ImageDecodeOptions options;
      options.mode = ImageDecodeMode::kUnchanged;
      options.max_width = kLargestDecodeSide;
      options.max_height = kLargestDecodeSide;
      FOVEA_ASSIGN_OR_RETURN(
          cv::Mat png,
          DecodeImage(image.compressed(), options, "image.compressed"));
      decoded = std::move(png);
    } else if (!image.data().empty()) {
      int type = -1;
      if (image.encoding() == "16UC1" || image.encoding() == "mono16") {
        type = CV_16UC1;
      } else if (image.encoding() == "32FC1") {
        type = CV_32FC1;
      } else if (image.encoding() == "mono8" || image.encoding() == "8UC1") {
        type = CV_8UC1;
      }
      const size_t needed = size_t{image.step()} * image.height();
      if (type >= 0 && image.step() > 0 && image.data().size() >= needed) {
        decoded = cv::Mat(image.height(), image.width(), type,
                          const_cast<char*>(image.data().data()), image.step())
                      .clone();
      }
    }
  } catch (const cv::Exception& e) {
    return absl::InvalidArgumentError(
        absl::StrCat("undecodable saliency map: ", e.what()));
  }
  if (decoded.empty() || decoded.channels() != 1) {
    return absl::InvalidArgumentError(
        "saliency map is neither a grey PNG nor a raw grey image");
  }
  cv::Mat map;
  switch (decoded.depth()) {
    case CV_16U:
      decoded.convertTo(map, CV_32F, 1.0 / 65535.0);
      break;
    case CV_8U:
      decoded.convertTo(map, CV_32F, 1.0 / 255.0);
      break;
    default:
      decoded.convertTo(map, CV_32F);
      cv::patchNaNs(map, 0.0);
      break;
  }
  return map;
}

// A [0, 1] map as a colour-mapped BGR image.
cv::Mat ColourMap(const cv::Mat& map) {
  cv::Mat grey;
  map.convertTo(grey, CV_8U, 255.0);
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
  return colour;
}

// A distinct BGR colour for index i.
cv::Scalar DistinctColour(int i) {
  const double hue = std::fmod(i * kGoldenRatioConjugate, 1.0) * 180.0;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 220, 255));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

void DrawLabel(cv::Mat& image, const std::string& text, cv::Point at,
               double scale) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

// Numbered circles, in list order (most salient first), the first largest.
void DrawPoints(cv::Mat& image, const PointList& points) {
  const int n = points.size();
  const double first_radius = std::max<double>(
      kMinRadiusPx, std::min(image.cols, image.rows) * kFirstRadiusFraction);
  for (int i = n - 1; i >= 0; --i) {  // the most salient drawn on top
    const fovea::v1::AttentionPoint& point = points[i];
    const double shrink =
        n > 1 ? (1.0 - kLastRadiusFraction) * i / (n - 1) : 0.0;
    const int radius = static_cast<int>(
        std::max<double>(kMinRadiusPx, first_radius * (1.0 - shrink)));
    const cv::Point centre(static_cast<int>(point.u()),
                           static_cast<int>(point.v()));
    const cv::Scalar colour =
        i == 0 ? cv::Scalar(0, 0, 255) : DistinctColour(i);
    cv::circle(image, centre, radius, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
    cv::circle(image, centre, radius, colour, 2, cv::LINE_AA);
    cv::circle(image, centre, 2, colour, cv::FILLED, cv::LINE_AA);
    DrawLabel(image, absl::StrCat(point.rank()),
              centre + cv::Point(radius / 2 + 3, -radius / 2 - 3), 0.6);
  }
}

// Keeps a map's name safe as part of a file name.
std::string SafeName(absl::string_view name) {
  std::string safe;
  for (char c : name) {
    safe +=
        absl::ascii_isalnum(c) || c == '_' || c == '-' || c == '.' ? c : '_';
  }
  return safe.empty() ? "unnamed" : safe;
}

std::string FormatPoint(const fovea::v1::Point3& p) {
  return absl::StrFormat("(%.3f, %.3f, %.3f)", p.x(), p.y(), p.z());
}

absl::Status CreateDir(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    return absl::InternalError(
        absl::StrCat("cannot create ", dir, ": ", error.message()));
  }
  return absl::OkStatus();
}

}  // namespace

std::string ToJson(const google::protobuf::Message& message, bool pretty) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = pretty;
  options.always_print_primitive_fields = true;
  std::string json;
  const auto status =
      google::protobuf::util::MessageToJsonString(message, &json, options);
  if (!status.ok()) {
    return absl::StrCat("{\"error\": \"cannot print as JSON: ",
                        status.message().as_string(), "\"}");
  }
  if (!pretty && !json.empty() && json.back() == '\n') json.pop_back();
  return json;
}

void PrintDetectTable(const fovea::v1::DetectResponse& response,
                      absl::Duration round_trip, std::ostream& out) {
  out << absl::StrFormat("%d attention points (request %s)\n",
                         response.points_size(), response.request_id());
  out << absl::StrFormat("%4s %5s %5s %8s %8s %8s %8s\n", "rank", "u", "v",
                         "x m", "y m", "z m", "saliency");
  for (const fovea::v1::AttentionPoint& p : response.points()) {
    out << absl::StrFormat("%4d %5d %5d %8.3f %8.3f %8.3f %8.3f\n", p.rank(),
                           p.u(), p.v(), p.point().x(), p.point().y(),
                           p.point().z(), p.saliency());
  }
  if (response.has_support_plane()) {
    const fovea::v1::SupportPlane& plane = response.support_plane();
    out << absl::StrFormat(
        "support plane: n %s, d %.3f m, %d inliers; %s of %d candidates, "
        "score %.2f (%d objects on it, %.2f m^2, %.2f m away, tilt %.1f "
        "deg%s)\n",
        FormatPoint(plane.normal()), plane.d(), plane.inlier_count(),
        plane.given() ? "given" : "chosen", plane.candidate_count(),
        plane.score().total(), plane.score().objects(), plane.score().area_m2(),
        plane.score().distance_m(), plane.score().tilt_deg(),
        plane.score().under_another() ? ", under another" : "");
  }
  double total = 0.0;
  if (response.timings_size() > 0) out << "timings:\n";
  for (const fovea::v1::StageTiming& timing : response.timings()) {
    out << absl::StrFormat("  %-24s %9.2f ms\n", timing.stage(),
                           timing.seconds() * 1e3);
    total += timing.seconds();
  }
  if (response.timings_size() > 0) {
    out << absl::StrFormat("  %-24s %9.2f ms\n", "(sum of stages)",
                           total * 1e3);
  }
  out << absl::StrFormat("round trip: %.2f ms\n",
                         absl::ToDoubleMilliseconds(round_trip));
}

std::string DescribeSegmentMessage(const fovea::v1::SegmentResponse& message,
                                   absl::Duration since_start) {
  std::vector<std::string> parts;
  if (message.attention_points_size() > 0) {
    std::vector<std::string> pixels;
    for (const fovea::v1::AttentionPoint& p : message.attention_points()) {
      pixels.push_back(absl::StrCat("(", p.u(), ",", p.v(), ")"));
    }
    parts.push_back(absl::StrCat("attention points ",
                                 message.attention_points_size(), ": ",
                                 absl::StrJoin(pixels, " ")));
  }
  if (message.has_support_plane()) {
    const fovea::v1::SupportPlane& plane = message.support_plane();
    parts.push_back(absl::StrFormat(
        "support plane n %s d %.3f m (%s of %d candidates, %d objects on "
        "it)",
        FormatPoint(plane.normal()), plane.d(),
        plane.given() ? "given" : "chosen", plane.candidate_count(),
        plane.score().objects()));
  }
  if (message.has_object()) {
    const fovea::v1::ObjectResult& o = message.object();
    parts.push_back(absl::StrFormat(
        "object %d: area %d px, box %d,%d %dx%d, score %.3f, centroid %s m, "
        "extent %s m, seed (%d,%d), server %.1f ms",
        o.index(), o.area(), o.box().u(), o.box().v(), o.box().width(),
        o.box().height(), o.score(), FormatPoint(o.centroid()),
        FormatPoint(o.extent()), o.seed().u(), o.seed().v(),
        o.seconds_since_request() * 1e3));
    if (o.has_oriented_box()) {
      const fovea::v1::OrientedBox& b = o.box_in_support();
      const fovea::v1::Quaternion& q = b.orientation();
      // The box in the support frame turns about z only.
      const double yaw_deg =
          2.0 * std::atan2(q.z(), q.w()) * 180.0 / 3.14159265358979323846;
      parts.push_back(absl::StrFormat(
          "  on the support: box %.3f x %.3f x %.3f m, yaw %.0f deg, top "
          "%.3f m above it, footprint %.4f m^2, centre %s m (camera)",
          b.size().x(), b.size().y(), b.size().z(), yaw_deg,
          o.height_above_support(), o.footprint_area(),
          FormatPoint(o.oriented_box().center())));
    }
    if (o.points().count() > 0) {
      parts.push_back(absl::StrFormat("  %d points (%s)", o.points().count(),
                                      o.points().indices_size() > 0
                                          ? "organized indices"
                                          : "xyz, float32"));
    }
  }
  if (message.last()) {
    const fovea::v1::SegmentSummary& s = message.summary();
    std::string last = absl::StrFormat(
        "last: %s, %d objects, coverage %.3f, server total %.1f ms",
        absl::AsciiStrToUpper(
            ShortName(fovea::v1::StopReason_descriptor(), s.stop_reason())),
        s.object_count(), s.scene_coverage(), s.seconds_total() * 1e3);
    for (const fovea::v1::StageTiming& t : s.timings()) {
      absl::StrAppend(
          &last, absl::StrFormat(", %s %.1f ms", t.stage(), t.seconds() * 1e3));
    }
    parts.push_back(std::move(last));
  }
  if (parts.empty()) parts.push_back("(empty message)");
  return absl::StrFormat("+%9.1f ms  %s",
                         absl::ToDoubleMilliseconds(since_start),
                         absl::StrJoin(parts, "; "));
}

void PrintCapabilities(const fovea::v1::GetCapabilitiesResponse& c,
                       std::ostream& out) {
  auto join_enum = [](const auto& values, auto name) {
    std::vector<std::string> names;
    for (int v : values) names.push_back(name(v));
    return names.empty() ? std::string("(none)") : absl::StrJoin(names, ", ");
  };
  auto join = [](const auto& values) {
    return values.empty() ? std::string("(none)") : absl::StrJoin(values, ", ");
  };
  out << absl::StrFormat("%-22s %s\n", "server version", c.server_version());
  out << absl::StrFormat("%-22s %s\n", "colour encodings",
                         join(c.color_encodings()));
  out << absl::StrFormat("%-22s %s\n", "depth encodings",
                         join(c.depth_encodings()));
  out << absl::StrFormat("%-22s %s\n", "compressed formats",
                         join(c.compressed_formats()));
  out << absl::StrFormat("%-22s %dx%d px\n", "largest frame", c.max_width(),
                         c.max_height());
  out << absl::StrFormat("%-22s %d bytes\n", "largest message",
                         c.max_message_bytes());
  out << absl::StrFormat(
      "%-22s %s\n", "saliency operators",
      join_enum(c.saliency_operators(), [](int v) {
        return SaliencyName(static_cast<fovea::v1::SaliencyOperator>(v));
      }));
  out << absl::StrFormat("%-22s %s\n", "pyramids",
                         join_enum(c.pyramids(), [](int v) {
                           return ShortName(fovea::v1::Pyramid_descriptor(), v);
                         }));
  out << absl::StrFormat(
      "%-22s %s\n", "normalizations", join_enum(c.normalizations(), [](int v) {
        return ShortName(fovea::v1::Normalization_descriptor(), v);
      }));
  out << absl::StrFormat(
      "%-22s %s\n", "extractions", join_enum(c.extractions(), [](int v) {
        return ShortName(fovea::v1::Extraction_descriptor(), v);
      }));
  out << absl::StrFormat("%-22s %s\n", "segmentation methods",
                         join_enum(c.segmentation_methods(), [](int v) {
                           return ShortName(
                               fovea::v1::SegmentationMethod_descriptor(), v);
                         }));
  out << absl::StrFormat("%-22s %s\n", "segment incremental",
                         c.segment_incremental() ? "yes" : "no");
  for (const fovea::v1::ModelVersion& model : c.models()) {
    out << absl::StrFormat("%-22s %s %s\n", "model", model.name(),
                           model.version());
  }
  if (c.has_default_detect_options()) {
    out << absl::StrFormat("%-22s %s\n", "default detect options",
                           ToJson(c.default_detect_options()));
  }
}

absl::StatusOr<std::vector<std::string>> WriteDetectOutputs(
    const std::string& dir, const fovea::v1::DetectResponse& response,
    const cv::Mat& color_bgr) {
  FOVEA_RETURN_IF_ERROR(CreateDir(dir));
  const std::filesystem::path root(dir);
  std::vector<std::string> written;
  auto write_png = [&](const std::string& name,
                       const cv::Mat& image) -> absl::Status {
    absl::Status status = WritePng(root / name, image);
    if (status.ok()) written.push_back((root / name).string());
    return status;
  };

  FOVEA_RETURN_IF_ERROR(
      WriteText(root / "response.json", ToJson(response, true)));
  written.push_back((root / "response.json").string());

  if (!color_bgr.empty()) {
    cv::Mat overlay = color_bgr.clone();
    DrawPoints(overlay, response.points());
    FOVEA_RETURN_IF_ERROR(write_png("overlay.png", overlay));
  }
  for (const fovea::v1::SaliencyMapImage& map_image : response.maps()) {
    absl::StatusOr<cv::Mat> map = DecodeMap(map_image.image());
    if (!map.ok()) {
      return absl::Status(map.status().code(),
                          absl::StrCat("map \"", map_image.name(),
                                       "\": ", map.status().message()));
    }
    const cv::Mat coloured = ColourMap(*map);
    const bool master =
        map_image.name() == "master" || map_image.name().empty();
    const std::string name =
        master ? "saliency.png"
               : absl::StrCat("saliency_", SafeName(map_image.name()), ".png");
    FOVEA_RETURN_IF_ERROR(write_png(name, coloured));
    if (master && !color_bgr.empty()) {
      cv::Mat resized = coloured;
      if (coloured.size() != color_bgr.size()) {
        cv::resize(coloured, resized, color_bgr.size(), 0, 0,
                   cv::INTER_NEAREST);
      }
      cv::Mat blended;
      cv::addWeighted(color_bgr, 1.0 - kOverlayAlpha, resized, kOverlayAlpha,
                      0.0, blended);
      DrawPoints(blended, response.points());
      FOVEA_RETURN_IF_ERROR(write_png("saliency_overlay.png", blended));
    }
  }
  return written;
}

absl::StatusOr<std::string> WriteObjectMask(
    const std::string& dir, const fovea::v1::ObjectResult& object) {
  FOVEA_RETURN_IF_ERROR(CreateDir(dir));
  absl::StatusOr<ByteMask> mask = DecodeRle(object.mask());
  if (!mask.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("object ", object.index(), ": ", mask.status().message()));
  }
  cv::Mat mask_image(static_cast<int>(mask->height),
                     static_cast<int>(mask->width), CV_8UC1,
                     mask->pixels.data());
  mask_image = mask_image * 255;
  const std::filesystem::path path =
      std::filesystem::path(dir) /
      absl::StrCat("mask_", object.index(), ".png");
  FOVEA_RETURN_IF_ERROR(WritePng(path, mask_image));
  return path.string();
}

absl::StatusOr<std::vector<std::string>> WriteSegmentOutputs(
    const std::string& dir,
    const std::vector<fovea::v1::SegmentResponse>& messages,
    const cv::Mat& color_bgr) {
  FOVEA_RETURN_IF_ERROR(CreateDir(dir));
  const std::filesystem::path root(dir);
  std::vector<std::string> written;

  std::string lines;
  for (const fovea::v1::SegmentResponse& message : messages) {
    absl::StrAppend(&lines, ToJson(message), "\n");
  }
  FOVEA_RETURN_IF_ERROR(WriteText(root / "responses.jsonl", lines));
  written.push_back((root / "responses.jsonl").string());

  cv::Mat overlay = color_bgr.empty() ? cv::Mat() : color_bgr.clone();
  for (const fovea::v1::SegmentResponse& message : messages) {
    if (!message.has_object()) continue;
    const fovea::v1::ObjectResult& object = message.object();
    absl::StatusOr<ByteMask> mask = DecodeRle(object.mask());
    if (!mask.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "object ", object.index(), ": ", mask.status().message()));
    }
    cv::Mat mask_image(static_cast<int>(mask->height),
                       static_cast<int>(mask->width), CV_8UC1,
                       mask->pixels.data());
    mask_image = mask_image * 255;

    if (overlay.empty() || mask_image.size() != overlay.size()) continue;
    const cv::Scalar colour = DistinctColour(static_cast<int>(object.index()));
    cv::Mat tint(overlay.size(), CV_8UC3, colour);
    cv::Mat blended;
    cv::addWeighted(overlay, 1.0 - kOverlayAlpha, tint, kOverlayAlpha, 0.0,
                    blended);
    blended.copyTo(overlay, mask_image);
    const fovea::v1::BoundingBox& box = object.box();
    cv::rectangle(overlay,
                  cv::Rect(box.u(), box.v(), box.width(), box.height()), colour,
                  2);
    DrawLabel(overlay, absl::StrCat(object.index()),
              cv::Point(box.u() + 3, box.v() + 18), 0.6);
  }
  if (!overlay.empty()) {
    if (!messages.empty()) DrawPoints(overlay, messages[0].attention_points());
    const std::filesystem::path path = root / "overlay.png";
    FOVEA_RETURN_IF_ERROR(WritePng(path, overlay));
    written.push_back(path.string());
  }
  return written;
}

}  // namespace fovea::client
