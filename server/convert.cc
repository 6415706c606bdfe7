#include "server/convert.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/frame/image_codec.h"
#include "core/pipeline/saliency_registry.h"

namespace fovea::server {
namespace {

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

// Largest value of one channel of `target_color_rgb`.
constexpr uint32_t kMaxColorValue = 255;
// Full scale of a 16-bit saliency PNG (frame.proto, SaliencyMapImage).
constexpr double kPngFullScale = 65535.0;

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

absl::Status UnknownEnumValue(const std::string& field, int value) {
  return absl::InvalidArgumentError(
      absl::StrCat(field, ": unknown value ", value));
}

// By name: the wire value whose name is the registry row's in upper case
// (saliency_registry.h).
absl::StatusOr<SaliencyOp> FromProto(v1::SaliencyOperator op,
                                     const std::string& field) {
  if (op == v1::SALIENCY_OPERATOR_UNSPECIFIED) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": an operator is required"));
  }
  const SaliencyOperator* row = nullptr;
  if (v1::SaliencyOperator_IsValid(op)) {
    row = FindSaliencyOperator(
        absl::AsciiStrToLower(v1::SaliencyOperator_Name(op)));
  }
  if (row == nullptr) return UnknownEnumValue(field, op);
  return row->op;
}

// The FromProto overloads below leave `out` alone for UNSPECIFIED, so the
// core default stands.
absl::Status FromProto(v1::Pyramid in, PyramidKind& out) {
  switch (in) {
    case v1::PYRAMID_UNSPECIFIED:
      return absl::OkStatus();
    case v1::NONE:
      out = PyramidKind::kNone;
      return absl::OkStatus();
    case v1::SIMPLE:
      out = PyramidKind::kSimple;
      return absl::OkStatus();
    case v1::ITTI_PYRAMID:
      out = PyramidKind::kItti;
      return absl::OkStatus();
    default:
      return UnknownEnumValue("options.pyramid", in);
  }
}

absl::Status FromProto(v1::LevelCombination in, LevelCombination& out) {
  switch (in) {
    case v1::LEVEL_COMBINATION_UNSPECIFIED:
      return absl::OkStatus();
    case v1::LEVELS_SUM:
      out = LevelCombination::kSum;
      return absl::OkStatus();
    case v1::LEVELS_MAX:
      out = LevelCombination::kMax;
      return absl::OkStatus();
    default:
      return UnknownEnumValue("options.level_combination", in);
  }
}

absl::Status FromProto(v1::Normalization in, NormalizationKind& out) {
  switch (in) {
    case v1::NORMALIZATION_UNSPECIFIED:
      return absl::OkStatus();
    case v1::LIN:
      out = NormalizationKind::kLin;
      return absl::OkStatus();
    case v1::NMS:
      out = NormalizationKind::kNms;
      return absl::OkStatus();
    case v1::NLM:
      out = NormalizationKind::kNlm;
      return absl::OkStatus();
    default:
      return UnknownEnumValue("options.normalization", in);
  }
}

absl::Status FromProto(v1::Fusion in, FusionKind& out) {
  switch (in) {
    case v1::FUSION_UNSPECIFIED:
      return absl::OkStatus();
    case v1::FUSION_SUM:
      out = FusionKind::kSum;
      return absl::OkStatus();
    case v1::FUSION_MAX:
      out = FusionKind::kMax;
      return absl::OkStatus();
    default:
      return UnknownEnumValue("options.fusion", in);
  }
}

// By name (Extractions() in core/pipeline/detect.h).
absl::Status FromProto(v1::Extraction in, ExtractionKind& out) {
  if (in == v1::EXTRACTION_UNSPECIFIED) return absl::OkStatus();
  if (!v1::Extraction_IsValid(in)) {
    return UnknownEnumValue("options.extraction", in);
  }
  absl::StatusOr<ExtractionKind> kind =
      ParseExtraction(absl::AsciiStrToLower(v1::Extraction_Name(in)));
  if (!kind.ok()) return UnknownEnumValue("options.extraction", in);
  out = *kind;
  return absl::OkStatus();
}

absl::StatusOr<std::vector<WeightedChannel>> ToChannels(
    const v1::DetectOptions& options) {
  std::vector<WeightedChannel> channels;
  channels.reserve(options.saliency_size());
  for (int i = 0; i < options.saliency_size(); ++i) {
    const v1::WeightedOperator& in = options.saliency(i);
    const std::string field = absl::StrCat("options.saliency[", i, "]");
    FOVEA_ASSIGN_OR_RETURN(SaliencyOp op, FromProto(in.op(), field + ".op"));
    const double weight = in.weight();
    if (!std::isfinite(weight) || weight < 0.0 || weight > 1e6) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".weight: ", weight,
          " is not in [0, 1e6] (weights are relative; 0 means 1)"));
    }
    channels.push_back({op, weight == 0.0 ? 1.0f : static_cast<float>(weight)});
  }
  return channels;
}

absl::Status CheckTopDownCues(const v1::DetectOptions& options) {
  const int n = options.target_color_rgb_size();
  if (n != 0 && n != 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "options.target_color_rgb: ", n, " values, expected 0 or 3"));
  }
  for (int i = 0; i < n; ++i) {
    if (options.target_color_rgb(i) > kMaxColorValue) {
      return absl::InvalidArgumentError(absl::StrCat(
          "options.target_color_rgb[", i, "]: ", options.target_color_rgb(i),
          " is above ", kMaxColorValue));
    }
  }
  const double sigma = options.location_prior_sigma_px();
  if (!std::isfinite(sigma) || sigma < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.location_prior_sigma_px: ", sigma,
                     " is not a finite value >= 0"));
  }
  return absl::OkStatus();
}

bool Uses(const DetectOptions& options, SaliencyOp op) {
  for (const WeightedChannel& c : options.channels) {
    if (c.op == op) return true;
  }
  return false;
}

// Copies the top-down cues (checked by CheckTopDownCues) into `out`; a cue
// channel without its cue is INVALID_ARGUMENT naming the missing field.
absl::Status ApplyTopDownCues(const v1::DetectOptions& options,
                              DetectOptions& out) {
  if (options.target_color_rgb_size() == 3) {
    for (int i = 0; i < 3; ++i) {
      out.target_color.rgb[i] =
          static_cast<uint8_t>(options.target_color_rgb(i));
    }
  } else if (Uses(out, SaliencyOp::kTargetColor)) {
    return absl::InvalidArgumentError(
        "options.target_color_rgb: TARGET_COLOR needs the colour, 3 values");
  }
  if (options.has_location_prior()) {
    out.location_prior.u = static_cast<float>(options.location_prior().u());
    out.location_prior.v = static_cast<float>(options.location_prior().v());
    if (options.location_prior_sigma_px() > 0.0) {
      out.location_prior.sigma_px =
          static_cast<float>(options.location_prior_sigma_px());
    }
  } else if (Uses(out, SaliencyOp::kLocationPrior)) {
    return absl::InvalidArgumentError(
        "options.location_prior: LOCATION_PRIOR needs the pixel it is "
        "centred on");
  }
  return absl::OkStatus();
}

Eigen::Vector3f ToVector3f(double x, double y, double z) {
  return Eigen::Vector3d(x, y, z).cast<float>();
}

// The scene options (core validates them, naming options.scene.*).
absl::Status ApplyScene(const v1::SceneOptions& in, DetectOptions& out) {
  SceneOptions& scene = out.scene;
  switch (in.sensor()) {
    case v1::SENSOR_MODEL_UNSPECIFIED:
    case v1::SENSOR_MODEL_GENERIC:
      scene.sensor = SensorKind::kGeneric;
      break;
    case v1::SENSOR_MODEL_KINECT_V1:
      scene.sensor = SensorKind::kKinectV1;
      break;
    case v1::SENSOR_MODEL_ACTIVE_STEREO:
      scene.sensor = SensorKind::kActiveStereo;
      break;
    default:
      return UnknownEnumValue("options.scene.sensor", in.sensor());
  }
  if (in.processing_width() != 0) {
    scene.processing_width =
        static_cast<int>(std::min<uint32_t>(in.processing_width(), 1u << 20));
  }
  if (in.has_gravity()) {
    scene.support.gravity =
        ToVector3f(in.gravity().x(), in.gravity().y(), in.gravity().z());
  }
  if (in.has_support_plane()) {
    const v1::Plane& plane = in.support_plane();
    Eigen::Vector4f p;
    p.head<3>() =
        ToVector3f(plane.normal().x(), plane.normal().y(), plane.normal().z());
    p[3] = static_cast<float>(plane.d());
    scene.support.plane = p;
  }
  if (in.has_workspace()) {
    const v1::Workspace& w = in.workspace();
    scene.workspace.min_depth_m = static_cast<float>(w.min_depth_m());
    scene.workspace.max_depth_m = static_cast<float>(w.max_depth_m());
    if (w.has_box()) {
      scene.workspace.box = Workspace::Box{
          ToVector3f(w.box().min().x(), w.box().min().y(), w.box().min().z()),
          ToVector3f(w.box().max().x(), w.box().max().y(), w.box().max().z())};
    }
  }
  return absl::OkStatus();
}

v1::Point3 ToPoint3(const Eigen::Vector3f& p) {
  v1::Point3 out;
  out.set_x(p.x());
  out.set_y(p.y());
  out.set_z(p.z());
  return out;
}

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
        const double units = std::round(row[u] / depth_scale);
        const uint16_t value =
            (std::isfinite(units) && units > 0.0 && units <= 65535.0)
                ? static_cast<uint16_t>(units)
                : 0;
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

absl::StatusOr<DetectOptions> ToDetectOptions(
    const v1::DetectOptions& options) {
  DetectOptions out;
  if (options.saliency_size() > 0) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<WeightedChannel> channels,
                           ToChannels(options));
    out.channels = std::move(channels);
  }
  for (absl::Status status :
       {FromProto(options.pyramid(), out.pyramid),
        FromProto(options.level_combination(), out.level_combination),
        FromProto(options.normalization(), out.normalization),
        FromProto(options.fusion(), out.fusion),
        FromProto(options.extraction(), out.extraction),
        CheckTopDownCues(options)}) {
    if (!status.ok()) return status;
  }
  if (options.max_points() > static_cast<uint32_t>(kMaxAttentionPoints)) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.max_points: ", options.max_points(), " is above ",
                     kMaxAttentionPoints));
  }
  if (options.max_points() != 0) {
    out.max_points = static_cast<int>(options.max_points());
  }
  out.keep_channel_maps = options.return_channel_maps();
  if (options.has_split_at_surface_edges()) {
    out.split_at_surface_edges = options.split_at_surface_edges();
  }
  FOVEA_RETURN_IF_ERROR(ApplyTopDownCues(options, out));
  FOVEA_RETURN_IF_ERROR(ApplyScene(options.scene(), out));

  // Core names the field itself ("options.saliency: 'ph' is given more
  // than once ...").
  FOVEA_RETURN_IF_ERROR(Validate(out));
  return out;
}

v1::SaliencyOperator ToProtoEnum(SaliencyOp op) {
  v1::SaliencyOperator value = v1::SALIENCY_OPERATOR_UNSPECIFIED;
  const SaliencyOperator* row = FindSaliencyOperator(op);
  if (row != nullptr) {
    v1::SaliencyOperator_Parse(absl::AsciiStrToUpper(AbslView(row->name)),
                               &value);
  }
  return value;
}

v1::SegmentationMethod ToProtoEnum(SegmentMethod method) {
  v1::SegmentationMethod value = v1::SEGMENTATION_METHOD_UNSPECIFIED;
  v1::SegmentationMethod_Parse(
      absl::AsciiStrToUpper(AbslView(SegmentMethodName(method))), &value);
  return value;
}

v1::Pyramid ToProtoEnum(PyramidKind pyramid) {
  switch (pyramid) {
    case PyramidKind::kNone:
      return v1::NONE;
    case PyramidKind::kSimple:
      return v1::SIMPLE;
    case PyramidKind::kItti:
      return v1::ITTI_PYRAMID;
  }
  return v1::PYRAMID_UNSPECIFIED;
}

v1::LevelCombination ToProtoEnum(LevelCombination combination) {
  switch (combination) {
    case LevelCombination::kSum:
      return v1::LEVELS_SUM;
    case LevelCombination::kMax:
      return v1::LEVELS_MAX;
  }
  return v1::LEVEL_COMBINATION_UNSPECIFIED;
}

v1::Normalization ToProtoEnum(NormalizationKind normalization) {
  switch (normalization) {
    case NormalizationKind::kLin:
      return v1::LIN;
    case NormalizationKind::kNms:
      return v1::NMS;
    case NormalizationKind::kNlm:
      return v1::NLM;
  }
  return v1::NORMALIZATION_UNSPECIFIED;
}

v1::Fusion ToProtoEnum(FusionKind fusion) {
  switch (fusion) {
    case FusionKind::kSum:
      return v1::FUSION_SUM;
    case FusionKind::kMax:
      return v1::FUSION_MAX;
  }
  return v1::FUSION_UNSPECIFIED;
}

v1::Extraction ToProtoEnum(ExtractionKind extraction) {
  v1::Extraction value = v1::EXTRACTION_UNSPECIFIED;
  v1::Extraction_Parse(
      absl::AsciiStrToUpper(AbslView(ExtractionName(extraction))), &value);
  return value;
}

v1::DetectOptions ToProtoDetectOptions(const DetectOptions& options) {
  v1::DetectOptions out;
  for (const WeightedChannel& channel : options.channels) {
    v1::WeightedOperator* op = out.add_saliency();
    op->set_op(ToProtoEnum(channel.op));
    op->set_weight(channel.weight);
  }
  out.set_pyramid(ToProtoEnum(options.pyramid));
  out.set_level_combination(ToProtoEnum(options.level_combination));
  out.set_normalization(ToProtoEnum(options.normalization));
  out.set_fusion(ToProtoEnum(options.fusion));
  out.set_extraction(ToProtoEnum(options.extraction));
  out.set_max_points(static_cast<uint32_t>(options.max_points));
  out.set_return_channel_maps(options.keep_channel_maps);
  out.set_split_at_surface_edges(options.split_at_surface_edges);
  v1::SceneOptions* scene = out.mutable_scene();
  switch (options.scene.sensor) {
    case SensorKind::kGeneric:
      scene->set_sensor(v1::SENSOR_MODEL_GENERIC);
      break;
    case SensorKind::kKinectV1:
      scene->set_sensor(v1::SENSOR_MODEL_KINECT_V1);
      break;
    case SensorKind::kActiveStereo:
      scene->set_sensor(v1::SENSOR_MODEL_ACTIVE_STEREO);
      break;
  }
  scene->set_processing_width(
      static_cast<uint32_t>(options.scene.processing_width));
  return out;
}

absl::StatusOr<std::string> EncodeSaliencyPng(const cv::Mat& map) {
  if (map.type() != CV_32FC1 || map.empty()) {
    return absl::InternalError(
        absl::StrCat("saliency map is not a non-empty CV_32FC1 image (type ",
                     map.type(), ", ", map.cols, "x", map.rows, ")"));
  }
  try {
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
  } catch (const std::exception& e) {
    return absl::InternalError(
        absl::StrCat("saliency map: PNG encoding failed: ", e.what()));
  }
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

namespace {

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
      method = ParseSegmentMethod(
          absl::AsciiStrToLower(v1::SegmentationMethod_Name(request.method())));
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
  return options;
}

v1::RleMask ToRleMask(const cv::Mat& mask) {
  v1::RleMask rle;
  rle.set_height(static_cast<uint32_t>(mask.rows));
  rle.set_width(static_cast<uint32_t>(mask.cols));
  // Column-major runs, starting with a (possibly empty) run of zeros.
  bool inside = false;
  uint32_t run = 0;
  for (int u = 0; u < mask.cols; ++u) {
    for (int v = 0; v < mask.rows; ++v) {
      const bool here = mask.at<unsigned char>(v, u) != 0;
      if (here != inside) {
        rle.add_counts(run);
        run = 0;
        inside = here;
      }
      ++run;
    }
  }
  if (mask.total() > 0) rle.add_counts(run);
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
