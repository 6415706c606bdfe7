// Detect responses: core's DetectResult to the wire's v1::DetectResponse,
// with the saliency maps as 16-bit PNGs and the support plane (convert.h).
#include <exception>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/frame/image_codec.h"
#include "server/convert.h"
#include "server/convert_internal.h"

namespace fovea::server {
namespace {

using convert_internal::ToPoint3;

// Full scale of a 16-bit saliency PNG (frame.proto, SaliencyMapImage).
constexpr double kPngFullScale = 65535.0;

absl::Status AddMap(const std::string& name, const cv::Mat& map,
                    v1::DetectResponse& response) {
  absl::StatusOr<std::string> png = EncodeSaliencyPng(map);
  if (!png.ok()) {
    return absl::Status(
        png.status().code(),
        absl::StrCat("map '", name, "': ", png.status().message()));
  }
  v1::SaliencyMapImage* out = response.add_maps();
  out->set_name(name);
  out->mutable_image()->set_width(map.cols);
  out->mutable_image()->set_height(map.rows);
  out->mutable_image()->set_compressed(*std::move(png));
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::string> EncodeSaliencyPng(const cv::Mat& map) {
  if (map.type() != CV_32FC1 || map.empty()) {
    return absl::InternalError(
        absl::StrCat("saliency map is not a non-empty CV_32FC1 image (type ",
                     map.type(), ", ", map.cols, "x", map.rows, ")"));
  }
  cv::Mat finite = map.clone();
  cv::patchNaNs(finite, 0.0);
  cv::Mat pixels;
  // convertTo rounds and saturates to [0, 65535].
  finite.convertTo(pixels, CV_16UC1, kPngFullScale);
  absl::StatusOr<std::string> png = EncodePng(pixels);
  if (!png.ok()) {
    return absl::InternalError(absl::StrCat(
        "saliency map: PNG encoding failed: ", png.status().message()));
  }
  return png;
}

v1::SupportPlane ToProtoSupportPlane(const SupportPlane& plane) {
  v1::SupportPlane out;
  *out.mutable_normal() = ToPoint3(plane.normal);
  out.set_d(plane.d);
  out.set_inlier_count(static_cast<uint32_t>(plane.inlier_count));
  out.set_candidate_count(static_cast<uint32_t>(plane.candidate_count));
  v1::SupportScore* score = out.mutable_score();
  score->set_total(plane.score.total);
  score->set_objects(static_cast<uint32_t>(plane.score.objects));
  score->set_area_m2(plane.score.area_m2);
  score->set_distance_m(plane.score.distance_m);
  score->set_tilt_deg(plane.score.tilt_deg);
  score->set_under_another(plane.score.under_another);
  out.set_given(plane.given);
  return out;
}

absl::StatusOr<v1::DetectResponse> ToDetectResponse(
    const DetectResult& result, const v1::DetectRequest& request) {
  v1::DetectResponse response;
  response.set_request_id(request.request_id());
  response.set_frame_id(request.frame().frame_id());
  response.set_stamp_ns(request.frame().stamp_ns());

  for (size_t i = 0; i < result.points.size(); ++i) {
    const AttentionPoint& in = result.points[i];
    v1::AttentionPoint* out = response.add_points();
    out->set_u(static_cast<uint32_t>(in.u));
    out->set_v(static_cast<uint32_t>(in.v));
    *out->mutable_point() = ToPoint3(in.point);
    out->set_saliency(in.saliency);
    out->set_rank(static_cast<uint32_t>(i));
  }

  *response.mutable_support_plane() = ToProtoSupportPlane(result.plane);

  if (request.options().return_saliency_map()) {
    FOVEA_RETURN_IF_ERROR(AddMap("master", result.master, response));
  }
  if (request.options().return_channel_maps()) {
    for (const NamedMap& map : result.channel_maps) {
      FOVEA_RETURN_IF_ERROR(AddMap(map.name, map.map, response));
    }
  }

  for (const StageTiming& timing : result.timings) {
    v1::StageTiming* out = response.add_timings();
    out->set_stage(timing.stage);
    out->set_seconds(timing.seconds);
  }
  return response;
}

}  // namespace fovea::server
