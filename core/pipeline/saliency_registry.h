#ifndef FOVEA_CORE_PIPELINE_SALIENCY_REGISTRY_H_
#define FOVEA_CORE_PIPELINE_SALIENCY_REGISTRY_H_

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/frame/organized_cloud.h"
#include "core/pipeline/detect.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea {

// The one table of saliency operators. Everything that names, converts,
// lists or runs an operator reads it: ParseSaliencyOps and SaliencyOpName,
// ChannelComputer, the server's conversion and capabilities (the wire value
// is the proto enum value whose name is the row's name in upper case:
// "target_color" is TARGET_COLOR), fovea-client's names (read from the
// proto descriptor, so the same), fovea-eval's and fovea-bench's flags.
// Adding an operator: its file pair in core/saliency/ and its test, a
// SaliencyOp value, one row here, one value in SaliencyOperator in
// proto/fovea/v1/detect.proto (tests/server/registries_test checks that
// every row is reachable through each layer, and every wire value has a
// row).

// What an operator's map is computed from.
enum class OperatorDomain {
  // The organized cloud, the support plane and the table scene of one
  // pyramid level; run per level under a feature pyramid.
  kGeometry,
  // The colour image (level 0); multi-scale itself, so the pyramid option
  // does not apply.
  kImage,
};

// One operator's inputs. For kImage operators `cloud` is level 0 (whose
// `color` they read).
struct OperatorInput {
  const OrganizedCloud& cloud;
  const SupportPlane& plane;
  const TableScene& table;
  const DetectOptions& options;
};

struct SaliencyOperator {
  SaliencyOp op;
  // The one spelling, everywhere: lower case, words joined by '_'.
  std::string_view name;
  OperatorDomain domain;
  // The map, CV_32FC1 of the input's size, before normalisation.
  absl::StatusOr<cv::Mat> (*compute)(const OperatorInput& input);
  // The pyramid level a kGeometry operator runs on without a feature
  // pyramid (its map resampled to level 0); null: level 0.
  int (*level_without_pyramid)(const DetectOptions& options) = nullptr;
};

// Every operator, in the wire contract's order.
absl::Span<const SaliencyOperator> SaliencyOperators();

// The row of `op` or of `name`; null when there is none.
const SaliencyOperator* FindSaliencyOperator(SaliencyOp op);
const SaliencyOperator* FindSaliencyOperator(std::string_view name);

// "ph sh rso ...": every name, for error messages and help texts.
std::string SaliencyOperatorNames();

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_SALIENCY_REGISTRY_H_
