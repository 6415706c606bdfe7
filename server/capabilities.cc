#include "server/capabilities.h"

#include <array>
#include <iterator>
#include <type_traits>
#include <vector>

#include "core/frame/sensor_model.h"
#include "core/pipeline/saliency_registry.h"
#include "server/convert.h"

#ifndef FOVEA_VERSION
#error "FOVEA_VERSION must be defined by the build (server/CMakeLists.txt)"
#endif

namespace fovea::server {
namespace {

constexpr std::array kAllPyramids = {PyramidKind::kNone, PyramidKind::kSimple,
                                     PyramidKind::kItti};
constexpr std::array kAllNormalizations = {
    NormalizationKind::kLin, NormalizationKind::kNms, NormalizationKind::kNlm};

// The values of `all` for which `set(options, value)` on default options
// passes Validate.
template <typename Range, typename Setter>
auto Accepted(const Range& all, Setter set) {
  using T = std::decay_t<decltype(*std::begin(all))>;
  std::vector<T> accepted;
  for (T value : all) {
    DetectOptions options;
    set(options, value);
    if (Validate(options).ok()) accepted.push_back(value);
  }
  return accepted;
}

}  // namespace

std::string_view ServerVersion() { return FOVEA_VERSION; }

std::vector<SaliencyOp> ImplementedSaliencyOps() {
  std::vector<SaliencyOp> all;
  for (const SaliencyOperator& row : SaliencyOperators()) all.push_back(row.op);
  return Accepted(all, [](DetectOptions& options, SaliencyOp op) {
    options.channels = {{op, 1.0f}};
  });
}

std::vector<PyramidKind> ImplementedPyramids() {
  return Accepted(kAllPyramids, [](DetectOptions& options, PyramidKind kind) {
    options.pyramid = kind;
  });
}

std::vector<NormalizationKind> ImplementedNormalizations() {
  return Accepted(kAllNormalizations,
                  [](DetectOptions& options, NormalizationKind kind) {
                    options.normalization = kind;
                  });
}

std::vector<ExtractionKind> ImplementedExtractions() {
  std::vector<ExtractionKind> all;
  for (const Extraction& row : Extractions()) all.push_back(row.kind);
  return Accepted(all, [](DetectOptions& options, ExtractionKind kind) {
    options.extraction = kind;
  });
}

v1::GetCapabilitiesResponse BuildCapabilities(
    const FrameLimits& limits, uint64_t max_message_bytes,
    const std::vector<std::pair<std::string, std::string>>& model_versions) {
  v1::GetCapabilitiesResponse out;
  out.set_server_version(std::string(ServerVersion()));
  for (const char* encoding : {"rgb8", "bgr8"})
    out.add_color_encodings(encoding);
  for (const char* encoding : {"16UC1", "32FC1"}) {
    out.add_depth_encodings(encoding);
  }
  for (const char* format : {"png", "jpeg"}) out.add_compressed_formats(format);
  out.set_max_width(limits.max_width);
  out.set_max_height(limits.max_height);
  out.set_max_message_bytes(max_message_bytes);
  for (SaliencyOp op : ImplementedSaliencyOps()) {
    out.add_saliency_operators(ToProtoEnum(op));
  }
  for (PyramidKind kind : ImplementedPyramids()) {
    out.add_pyramids(ToProtoEnum(kind));
  }
  for (NormalizationKind kind : ImplementedNormalizations()) {
    out.add_normalizations(ToProtoEnum(kind));
  }
  for (ExtractionKind kind : ImplementedExtractions()) {
    out.add_extractions(ToProtoEnum(kind));
  }
  for (const SegmentMethodRow& row : SegmentMethods()) {
    out.add_segmentation_methods(ToProtoEnum(row.method));
  }
  for (const auto& [name, version] : model_versions) {
    v1::ModelVersion* model = out.add_models();
    model->set_name(name);
    model->set_version(version);
  }
  out.set_segment_incremental(true);
  for (const NamedValue<SensorKind>& sensor : SensorKinds()) {
    out.add_sensor_models(ToProtoEnum(sensor.value));
  }
  *out.mutable_default_detect_options() = ToProtoDetectOptions(DetectOptions{});
  return out;
}

}  // namespace fovea::server
