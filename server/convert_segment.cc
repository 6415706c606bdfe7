// Segmentation: the wire's Segment and SegmentIncremental requests to
// core's options, and core's results to the stream's messages (convert.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "proto/enum_names.h"
#include "server/convert.h"
#include "server/convert_internal.h"

namespace fovea::server {
namespace {

using convert_internal::ToPoint3;

// Pixels of a request as cv::Points; INVALID_ARGUMENT naming `field` for
// too many or for coordinates beyond any frame (core checks the frame's
// own size).
absl::StatusOr<std::vector<cv::Point>> ToPixels(
    const google::protobuf::RepeatedPtrField<v1::AttentionPixel>& pixels,
    std::string_view field) {
  if (pixels.size() > kMaxAttentionPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat(AbslView(field), ": ", pixels.size(), " given, at most ",
                     kMaxAttentionPoints, " allowed"));
  }
  constexpr uint32_t kMaxCoordinate = 1 << 16;
  std::vector<cv::Point> points;
  for (int i = 0; i < pixels.size(); ++i) {
    const v1::AttentionPixel& p = pixels.Get(i);
    if (p.u() >= kMaxCoordinate || p.v() >= kMaxCoordinate) {
      return absl::InvalidArgumentError(absl::StrCat(AbslView(field), "[", i,
                                                     "]: (", p.u(), ", ", p.v(),
                                                     ") is beyond any frame"));
    }
    points.emplace_back(static_cast<int>(p.u()), static_cast<int>(p.v()));
  }
  return points;
}

// A segmentation request's detect_options, errors prefixed with the field.
absl::StatusOr<DetectOptions> ToNestedDetectOptions(
    const v1::DetectOptions& options) {
  absl::StatusOr<DetectOptions> detect = ToDetectOptions(options);
  if (!detect.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("detect_options.", detect.status().message()));
  }
  return detect;
}

// The request's object_points, errors naming the field.
absl::StatusOr<ObjectPointsOptions> ToObjectPointsOptions(
    const v1::ObjectPointsOptions& in) {
  ObjectPointsOptions out;
  switch (in.format()) {
    case v1::ObjectPointsOptions::FORMAT_UNSPECIFIED:
      out.format = ObjectPointsFormat::kNone;
      break;
    case v1::ObjectPointsOptions::FORMAT_INDICES:
      out.format = ObjectPointsFormat::kIndices;
      break;
    case v1::ObjectPointsOptions::FORMAT_XYZ:
      out.format = ObjectPointsFormat::kXyz;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("object_points.format: unknown value ",
                       static_cast<int>(in.format())));
  }
  if (in.max_points() > static_cast<uint32_t>(kMaxObjectPoints)) {
    return absl::InvalidArgumentError(
        absl::StrCat("object_points.max_points must be at most ",
                     kMaxObjectPoints, ", got ", in.max_points()));
  }
  out.max_points = static_cast<int>(in.max_points());
  return out;
}

v1::Quaternion ToProtoQuaternion(const Eigen::Quaternionf& q) {
  v1::Quaternion out;
  out.set_x(q.x());
  out.set_y(q.y());
  out.set_z(q.z());
  out.set_w(q.w());
  return out;
}

v1::OrientedBox ToProtoBox(const OrientedBox& box) {
  v1::OrientedBox out;
  *out.mutable_center() = ToPoint3(box.center);
  *out.mutable_orientation() = ToProtoQuaternion(box.orientation);
  v1::Vector3* size = out.mutable_size();
  size->set_x(box.size.x());
  size->set_y(box.size.y());
  size->set_z(box.size.z());
  return out;
}

}  // namespace

absl::StatusOr<SegmentOptions> ToSegmentOptions(
    const v1::SegmentRequest& request) {
  SegmentOptions options;
  FOVEA_ASSIGN_OR_RETURN(DetectOptions detect,
                         ToNestedDetectOptions(request.detect_options()));
  options.detect = std::move(detect);
  // By name: the value whose name is a segment method row's in upper case
  // (core/pipeline/segment.h); UNSPECIFIED is the default method.
  if (request.method() != v1::SEGMENTATION_METHOD_UNSPECIFIED) {
    absl::StatusOr<SegmentMethod> method = absl::InvalidArgumentError("");
    if (v1::SegmentationMethod_IsValid(request.method())) {
      method = ParseSegmentMethod(v1::ShortEnumName(
          *v1::SegmentationMethod_descriptor()->FindValueByNumber(
              request.method())));
    }
    if (!method.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "method: unknown value ", static_cast<int>(request.method())));
    }
    options.method = *method;
  }
  FOVEA_ASSIGN_OR_RETURN(std::vector<cv::Point> seeds,
                         ToPixels(request.seeds(), "seeds"));
  options.seeds = std::move(seeds);
  options.max_objects =
      static_cast<int>(std::min<uint32_t>(request.max_objects(), 1u << 20));
  if (request.has_cover_scene()) options.cover_scene = request.cover_scene();
  FOVEA_ASSIGN_OR_RETURN(options.object_points,
                         ToObjectPointsOptions(request.object_points()));
  return options;
}

absl::StatusOr<IncrementalOptions> ToIncrementalOptions(
    const v1::SegmentIncrementalRequest& request) {
  IncrementalOptions options;
  FOVEA_ASSIGN_OR_RETURN(DetectOptions detect,
                         ToNestedDetectOptions(request.detect_options()));
  options.detect = std::move(detect);
  FOVEA_ASSIGN_OR_RETURN(
      std::vector<cv::Point> points,
      ToPixels(request.attention_points(), "attention_points"));
  options.attention_points = std::move(points);
  options.max_objects =
      static_cast<int>(std::min<uint32_t>(request.max_objects(), 1u << 20));
  const double budget = request.time_budget_seconds();
  if (!std::isfinite(budget) || budget < 0.0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "time_budget_seconds: must be a finite number >= 0, got ", budget));
  }
  options.time_budget_seconds = budget;
  FOVEA_ASSIGN_OR_RETURN(options.object_points,
                         ToObjectPointsOptions(request.object_points()));
  return options;
}

v1::SegmentationMethod ToProtoEnum(SegmentMethod method) {
  v1::SegmentationMethod value = v1::SEGMENTATION_METHOD_UNSPECIFIED;
  const auto* found = v1::FindEnumValueByShortName(
      *v1::SegmentationMethod_descriptor(), SegmentMethodName(method));
  if (found != nullptr) {
    value = static_cast<v1::SegmentationMethod>(found->number());
  }
  return value;
}

v1::RleMask ToRleMask(const cv::Mat& mask) {
  v1::RleMask rle;
  rle.set_height(static_cast<uint32_t>(mask.rows));
  rle.set_width(static_cast<uint32_t>(mask.cols));
  if (mask.empty()) return rle;
  FOVEA_CHECK(mask.type() == CV_8UC1);
  // Column-major runs, starting with a (possibly empty) run of zeros. An
  // object covers a small part of the frame: only the columns and rows of
  // its bounding box are read (down a column is a stride of a whole row,
  // so reading every pixel that way cost 0.3 ms per 640x480 mask); what
  // lies around the box is zeros, counted in bulk.
  const cv::Rect box = cv::boundingRect(mask);
  bool inside = false;
  uint32_t run = 0;
  const auto zeros = [&](int count) {
    if (count == 0) return;
    if (inside) {
      rle.add_counts(run);
      run = 0;
      inside = false;
    }
    run += static_cast<uint32_t>(count);
  };
  zeros(box.x * mask.rows);
  for (int u = box.x; u < box.x + box.width; ++u) {
    zeros(box.y);
    for (int v = box.y; v < box.y + box.height; ++v) {
      const bool here = mask.ptr<unsigned char>(v)[u] != 0;
      if (here != inside) {
        rle.add_counts(run);
        run = 0;
        inside = here;
      }
      ++run;
    }
    zeros(mask.rows - box.y - box.height);
  }
  zeros((mask.cols - box.x - box.width) * mask.rows);
  rle.add_counts(run);
  return rle;
}

v1::SegmentResponse ToPointsMessage(const std::vector<AttentionPoint>& points,
                                    const std::string& request_id,
                                    const SupportPlane* plane) {
  v1::SegmentResponse message;
  message.set_request_id(request_id);
  if (plane != nullptr)
    *message.mutable_support_plane() = ToProtoSupportPlane(*plane);
  for (size_t i = 0; i < points.size(); ++i) {
    v1::AttentionPoint* out = message.add_attention_points();
    out->set_u(static_cast<uint32_t>(points[i].u));
    out->set_v(static_cast<uint32_t>(points[i].v));
    *out->mutable_point() = ToPoint3(points[i].point);
    out->set_saliency(points[i].saliency);
    out->set_rank(static_cast<uint32_t>(i));
  }
  return message;
}

v1::SegmentResponse ToObjectMessage(const SegmentedObject& object,
                                    const std::string& request_id) {
  v1::SegmentResponse message;
  message.set_request_id(request_id);
  v1::ObjectResult* out = message.mutable_object();
  out->set_index(static_cast<uint32_t>(object.index));
  v1::AttentionPoint* seed = out->mutable_seed();
  seed->set_u(static_cast<uint32_t>(object.seed.u));
  seed->set_v(static_cast<uint32_t>(object.seed.v));
  *seed->mutable_point() = ToPoint3(object.seed.point);
  seed->set_saliency(object.seed.saliency);
  *out->mutable_mask() = ToRleMask(object.mask);
  v1::BoundingBox* box = out->mutable_box();
  box->set_u(static_cast<uint32_t>(object.box.x));
  box->set_v(static_cast<uint32_t>(object.box.y));
  box->set_width(static_cast<uint32_t>(object.box.width));
  box->set_height(static_cast<uint32_t>(object.box.height));
  out->set_area(static_cast<uint32_t>(object.area));
  out->set_score(object.score);
  *out->mutable_centroid() = ToPoint3(object.centroid);
  *out->mutable_extent() = ToPoint3(object.extent);
  out->set_seconds_since_request(object.seconds_since_start);
  if (object.geometry.has_value()) {
    const ObjectGeometry& g = *object.geometry;
    *out->mutable_oriented_box() = ToProtoBox(g.box);
    v1::Pose* frame = out->mutable_support_frame();
    *frame->mutable_position() = ToPoint3(g.support_origin);
    *frame->mutable_orientation() = ToProtoQuaternion(g.support_orientation);
    *out->mutable_box_in_support() = ToProtoBox(g.box_in_support);
    out->set_height_above_support(g.height_above_support);
    out->set_footprint_area(g.footprint_area_m2);
  }
  if (!object.point_indices.empty()) {
    v1::ObjectPoints* points = out->mutable_points();
    points->mutable_indices()->Reserve(
        static_cast<int>(object.point_indices.size()));
    for (const int i : object.point_indices) {
      points->add_indices(static_cast<uint32_t>(i));
    }
    points->set_count(static_cast<uint32_t>(object.point_indices.size()));
  } else if (!object.points.empty()) {
    v1::ObjectPoints* points = out->mutable_points();
    std::string* xyz = points->mutable_xyz();
    xyz->resize(object.points.size() * 3 * sizeof(float));
    char* at = xyz->data();
    static_assert(sizeof(float) == 4, "float32 on the wire");
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
                  "the wire's floats are little-endian, as this machine's");
    for (const Eigen::Vector3f& p : object.points) {
      std::memcpy(at, p.data(), 3 * sizeof(float));
      at += 3 * sizeof(float);
    }
    points->set_count(static_cast<uint32_t>(object.points.size()));
  }
  return message;
}

v1::SegmentResponse ToSummaryMessage(const SegmentSummary& summary,
                                     v1::StopReason stop_reason,
                                     const std::string& request_id) {
  v1::SegmentResponse message;
  message.set_request_id(request_id);
  message.set_last(true);
  v1::SegmentSummary* out = message.mutable_summary();
  out->set_stop_reason(stop_reason);
  out->set_object_count(static_cast<uint32_t>(summary.objects));
  out->set_scene_coverage(summary.scene_coverage);
  for (const StageTiming& timing : summary.timings) {
    v1::StageTiming* t = out->add_timings();
    t->set_stage(timing.stage);
    t->set_seconds(timing.seconds);
  }
  out->set_seconds_total(summary.total_seconds);
  return message;
}

}  // namespace fovea::server
