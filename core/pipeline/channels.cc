#include "core/pipeline/channels.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/pipeline/saliency_registry.h"
#include "core/pyramid/feature_pyramid.h"
#include "core/pyramid/normalization.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

MapNormalization ToMapNormalization(NormalizationKind kind) {
  switch (kind) {
    case NormalizationKind::kNms:
      return MapNormalization::kNms;
    case NormalizationKind::kNlm:
      return MapNormalization::kNlm;
    case NormalizationKind::kLin:
      break;
  }
  return MapNormalization::kLin;
}

FeaturePyramidOptions ToFeaturePyramidOptions(const DetectOptions& options) {
  FeaturePyramidOptions f = options.feature_pyramid;
  f.kind = options.pyramid == PyramidKind::kItti ? FeaturePyramidKind::kItti
                                                 : FeaturePyramidKind::kSimple;
  f.combination = options.level_combination == LevelCombination::kMax
                      ? ScaleCombination::kMax
                      : ScaleCombination::kSum;
  f.normalization = ToMapNormalization(options.normalization);
  f.normalization_options = options.normalization_options;
  return f;
}

}  // namespace

bool UsesCloudPyramid(const DetectOptions& options) {
  for (const WeightedChannel& c : options.channels) {
    const SaliencyOperator* row = FindSaliencyOperator(c.op);
    if (row == nullptr || row->domain == OperatorDomain::kImage) continue;
    if (options.pyramid != PyramidKind::kNone ||
        row->level_without_pyramid != nullptr) {
      return true;
    }
  }
  return false;
}

CloudPyramidOptions CloudPyramidLevels(const DetectOptions& options) {
  // Without a feature pyramid only SYM3D's level is needed.
  CloudPyramidOptions levels = options.cloud_pyramid;
  if (options.pyramid == PyramidKind::kNone) {
    levels.max_levels = std::min(levels.max_levels, options.sym3d_level + 1);
  }
  return levels;
}

ChannelComputer::ChannelComputer(const OrganizedCloud& cloud,
                                 const SupportPlane& plane,
                                 const TableScene& table,
                                 const DetectOptions& options,
                                 const CloudPyramid* pyramid)
    : cloud_(cloud),
      plane_(plane),
      table_(table),
      options_(options),
      prebuilt_(pyramid) {}

absl::StatusOr<const CloudPyramid*> ChannelComputer::Pyramid() {
  if (prebuilt_ == nullptr && !pyramid_.has_value()) {
    FOVEA_ASSIGN_OR_RETURN(
        CloudPyramid built,
        BuildCloudPyramid(cloud_, CloudPyramidLevels(options_)));
    pyramid_ = std::move(built);
  }
  const CloudPyramid* pyramid = prebuilt_ != nullptr ? prebuilt_ : &*pyramid_;
  if (tables_.size() != static_cast<size_t>(pyramid->size())) {
    tables_.assign(pyramid->size(), std::nullopt);
  }
  return pyramid;
}

absl::StatusOr<const TableScene*> ChannelComputer::TableAt(int level) {
  if (level == 0) return &table_;
  FOVEA_ASSIGN_OR_RETURN(const CloudPyramid* pyramid, Pyramid());
  if (level >= pyramid->size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("pyramid level ", level, " does not exist"));
  }
  if (!tables_[level].has_value()) {
    tables_[level] =
        PrepareTableScene(pyramid->levels[level], plane_, options_.table_scene);
  }
  return &*tables_[level];
}

const SaliencyOperator& ChannelComputer::Row(SaliencyOp op) {
  const SaliencyOperator* row = FindSaliencyOperator(op);
  FOVEA_CHECK(row != nullptr);  // Validate(DetectOptions) refused it
  return *row;
}

absl::StatusOr<cv::Mat> ChannelComputer::OperatorAt(SaliencyOp op, int level) {
  const OrganizedCloud* cloud = &cloud_;
  if (level > 0) {
    FOVEA_ASSIGN_OR_RETURN(const CloudPyramid* pyramid, Pyramid());
    cloud = &pyramid->levels[level];
  }
  FOVEA_ASSIGN_OR_RETURN(const TableScene* table, TableAt(level));
  return Row(op).compute({*cloud, plane_, *table, options_});
}

absl::StatusOr<cv::Mat> ChannelComputer::Compute(SaliencyOp op) {
  const SaliencyOperator& row = Row(op);
  if (row.domain == OperatorDomain::kImage) {
    FOVEA_ASSIGN_OR_RETURN(cv::Mat map,
                           row.compute({cloud_, plane_, table_, options_}));
    return NormalizeMap(map, ToMapNormalization(options_.normalization),
                        options_.normalization_options);
  }
  if (options_.pyramid != PyramidKind::kNone) {
    FOVEA_ASSIGN_OR_RETURN(const CloudPyramid* pyramid, Pyramid());
    const LevelFeature feature =
        [this, op](int level,
                   const OrganizedCloud& /*cloud*/) -> absl::StatusOr<cv::Mat> {
      return OperatorAt(op, level);
    };
    FOVEA_ASSIGN_OR_RETURN(
        Conspicuity conspicuity,
        BuildConspicuityMap(*pyramid, feature,
                            ToFeaturePyramidOptions(options_)));
    return OnCandidates(std::move(conspicuity.map));
  }
  // Single level: an operator may run on a coarser level (SYM3D needs a
  // kernel the size of an object) and be resampled to level 0.
  int level = 0;
  if (row.level_without_pyramid != nullptr) {
    FOVEA_ASSIGN_OR_RETURN(const CloudPyramid* pyramid, Pyramid());
    level = std::min(row.level_without_pyramid(options_), pyramid->size() - 1);
  }
  FOVEA_ASSIGN_OR_RETURN(cv::Mat map, OperatorAt(op, level));
  if (level > 0) {
    FOVEA_ASSIGN_OR_RETURN(const CloudPyramid* pyramid, Pyramid());
    FOVEA_ASSIGN_OR_RETURN(map, ResampleBetweenLevels(map, level, 0, *pyramid));
  }
  // Level-0 operators give zero off the candidates already; a resampled map
  // is smeared and masked again.
  return NormalizeMap(level > 0 ? OnCandidates(std::move(map)) : map,
                      ToMapNormalization(options_.normalization),
                      options_.normalization_options);
}

cv::Mat ChannelComputer::OnCandidates(cv::Mat map) const {
  cv::Mat masked(map.size(), CV_32FC1, cv::Scalar(0));
  map.copyTo(masked, table_.candidate);
  NormalizeLinear(masked);
  return masked;
}

}  // namespace fovea
