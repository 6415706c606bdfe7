// Detect options: the wire's v1::DetectOptions to core's DetectOptions
// (channels, enums, top-down cues, scene) and back, and the enum values on
// the wire (convert.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/pipeline/saliency_registry.h"
#include "proto/enum_names.h"
#include "server/convert.h"

namespace fovea::server {
namespace {

// Largest value of one channel of `target_color_rgb`.
constexpr uint32_t kMaxColorValue = 255;

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
    row = FindSaliencyOperator(v1::ShortEnumName(
        *v1::SaliencyOperator_descriptor()->FindValueByNumber(op)));
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
    case v1::PYRAMID_NONE:
      out = PyramidKind::kNone;
      return absl::OkStatus();
    case v1::PYRAMID_SIMPLE:
      out = PyramidKind::kSimple;
      return absl::OkStatus();
    case v1::PYRAMID_ITTI:
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
    case v1::LEVEL_COMBINATION_SUM:
      out = LevelCombination::kSum;
      return absl::OkStatus();
    case v1::LEVEL_COMBINATION_MAX:
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
    case v1::NORMALIZATION_LIN:
      out = NormalizationKind::kLin;
      return absl::OkStatus();
    case v1::NORMALIZATION_NMS:
      out = NormalizationKind::kNms;
      return absl::OkStatus();
    case v1::NORMALIZATION_NLM:
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
  absl::StatusOr<ExtractionKind> kind = ParseExtraction(
      v1::ShortEnumName(*v1::Extraction_descriptor()->FindValueByNumber(in)));
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
    case v1::SENSOR_MODEL_TIME_OF_FLIGHT:
      scene.sensor = SensorKind::kTimeOfFlight;
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

}  // namespace

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
    const auto* found = v1::FindEnumValueByShortName(
        *v1::SaliencyOperator_descriptor(), row->name);
    if (found != nullptr) {
      value = static_cast<v1::SaliencyOperator>(found->number());
    }
  }
  return value;
}

v1::Pyramid ToProtoEnum(PyramidKind pyramid) {
  switch (pyramid) {
    case PyramidKind::kNone:
      return v1::PYRAMID_NONE;
    case PyramidKind::kSimple:
      return v1::PYRAMID_SIMPLE;
    case PyramidKind::kItti:
      return v1::PYRAMID_ITTI;
  }
  return v1::PYRAMID_UNSPECIFIED;
}

v1::LevelCombination ToProtoEnum(LevelCombination combination) {
  switch (combination) {
    case LevelCombination::kSum:
      return v1::LEVEL_COMBINATION_SUM;
    case LevelCombination::kMax:
      return v1::LEVEL_COMBINATION_MAX;
  }
  return v1::LEVEL_COMBINATION_UNSPECIFIED;
}

v1::Normalization ToProtoEnum(NormalizationKind normalization) {
  switch (normalization) {
    case NormalizationKind::kLin:
      return v1::NORMALIZATION_LIN;
    case NormalizationKind::kNms:
      return v1::NORMALIZATION_NMS;
    case NormalizationKind::kNlm:
      return v1::NORMALIZATION_NLM;
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
  const auto* found = v1::FindEnumValueByShortName(*v1::Extraction_descriptor(),
                                                   ExtractionName(extraction));
  if (found != nullptr) value = static_cast<v1::Extraction>(found->number());
  return value;
}

v1::SensorModel ToProtoEnum(SensorKind sensor) {
  switch (sensor) {
    case SensorKind::kGeneric:
      return v1::SENSOR_MODEL_GENERIC;
    case SensorKind::kKinectV1:
      return v1::SENSOR_MODEL_KINECT_V1;
    case SensorKind::kActiveStereo:
      return v1::SENSOR_MODEL_ACTIVE_STEREO;
    case SensorKind::kTimeOfFlight:
      return v1::SENSOR_MODEL_TIME_OF_FLIGHT;
  }
  return v1::SENSOR_MODEL_UNSPECIFIED;
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
  scene->set_sensor(ToProtoEnum(options.scene.sensor));
  scene->set_processing_width(
      static_cast<uint32_t>(options.scene.processing_width));
  return out;
}

}  // namespace fovea::server
