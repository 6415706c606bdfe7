#include "core/pyramid/feature_pyramid.h"

#include <algorithm>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

// Highest level number an option may name (CloudPyramidOptions allows at
// most 16 levels, 0..15).
constexpr int kMaxLevel = 15;

absl::Status ValidateLevels(const std::vector<int>& levels,
                            absl::string_view field, int min_value) {
  if (levels.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("feature_pyramid.", field, " must not be empty"));
  }
  for (int level : levels) {
    if (level < min_value || level > kMaxLevel) {
      return absl::InvalidArgumentError(
          absl::StrCat("feature_pyramid.", field, " values must be in [",
                       min_value, ", ", kMaxLevel, "], got ", level));
    }
  }
  return absl::OkStatus();
}

cv::Size LevelSize(const CloudPyramid& pyramid, int level) {
  return {pyramid.levels[level].width(), pyramid.levels[level].height()};
}

// Runs `feature` on each level once and keeps the maps.
class FeatureCache {
 public:
  FeatureCache(const CloudPyramid& pyramid, const LevelFeature& feature)
      : pyramid_(pyramid), feature_(feature), maps_(pyramid.size()) {}

  absl::StatusOr<cv::Mat> Get(int level) {
    if (maps_[level].has_value()) return *maps_[level];
    FOVEA_ASSIGN_OR_RETURN(cv::Mat map,
                           feature_(level, pyramid_.levels[level]));
    const cv::Size expected = LevelSize(pyramid_, level);
    if (map.type() != CV_32FC1 || map.size() != expected) {
      return absl::InvalidArgumentError(
          absl::StrCat("feature map of level ", level, " must be CV_32FC1 ",
                       expected.width, "x", expected.height, ", got type ",
                       map.type(), " ", map.cols, "x", map.rows));
    }
    maps_[level] = map;
    return map;
  }

 private:
  const CloudPyramid& pyramid_;  // not owned; outlives the cache
  const LevelFeature& feature_;  // not owned; outlives the cache
  std::vector<std::optional<cv::Mat>> maps_;
};

// The (centre, surround) pairs whose levels all exist, in option order.
std::vector<FeatureScale> UsableScales(const FeaturePyramidOptions& options,
                                       int levels) {
  std::vector<FeatureScale> scales;
  if (options.kind == FeaturePyramidKind::kSimple) {
    for (int l : options.simple_levels) {
      if (l < levels) scales.push_back({l, -1});
    }
  } else {
    for (int c : options.itti_centres) {
      for (int d : options.itti_deltas) {
        if (c + d < levels) scales.push_back({c, c + d});
      }
    }
  }
  return scales;
}

// F_l (SIMPLE) or |F_c - up(F_s)| (ITTI), at the scale's centre level.
absl::StatusOr<cv::Mat> FeatureMap(const FeatureScale& scale,
                                   const CloudPyramid& pyramid,
                                   FeatureCache& cache) {
  absl::StatusOr<cv::Mat> centre = cache.Get(scale.centre);
  if (!centre.ok() || scale.surround < 0) return centre;
  FOVEA_ASSIGN_OR_RETURN(cv::Mat surround, cache.Get(scale.surround));
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat moved,
      ResampleBetweenLevels(surround, scale.surround, scale.centre, pyramid));
  cv::Mat difference;
  cv::absdiff(*centre, moved, difference);
  return difference;
}

// Folds `map` into `accumulator` by SUM or MAX.
void Combine(const cv::Mat& map, ScaleCombination combination,
             cv::Mat& accumulator) {
  if (accumulator.empty()) {
    accumulator = map.clone();
  } else if (combination == ScaleCombination::kSum) {
    accumulator += map;
  } else {
    cv::max(accumulator, map, accumulator);
  }
}

absl::StatusOr<Conspicuity> Build(const CloudPyramid& pyramid,
                                  const LevelFeature& feature,
                                  const FeaturePyramidOptions& options) {
  Conspicuity result;
  result.output_level = std::min(options.output_level, pyramid.size() - 1);
  result.scales = UsableScales(options, pyramid.size());
  if (result.scales.empty()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the pyramid has ", pyramid.size(), " levels; none of the ",
        options.kind == FeaturePyramidKind::kSimple
            ? "feature_pyramid.simple_levels"
            : "ITTI centre-surround pairs (itti_centres + itti_deltas)",
        " fits in it"));
  }
  FeatureCache cache(pyramid, feature);
  cv::Mat combined;
  for (const FeatureScale& scale : result.scales) {
    FOVEA_ASSIGN_OR_RETURN(cv::Mat map, FeatureMap(scale, pyramid, cache));
    FOVEA_ASSIGN_OR_RETURN(cv::Mat normalised,
                           NormalizeMap(map, options.normalization,
                                        options.normalization_options));
    FOVEA_ASSIGN_OR_RETURN(cv::Mat moved,
                           ResampleBetweenLevels(normalised, scale.centre,
                                                 result.output_level, pyramid));
    Combine(moved, options.combination, combined);
  }
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat full,
      ResampleBetweenLevels(combined, result.output_level, 0, pyramid));
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat map, NormalizeMap(cv::max(full, 0.0f), MapNormalization::kLin,
                                NormalizationOptions{}));
  result.map = std::move(map);
  return result;
}

}  // namespace

absl::Status Validate(const FeaturePyramidOptions& options) {
  if (options.output_level < 0 || options.output_level > kMaxLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("feature_pyramid.output_level must be in [0, ", kMaxLevel,
                     "], got ", options.output_level));
  }
  FOVEA_RETURN_IF_ERROR(
      ValidateLevels(options.simple_levels, "simple_levels", 0));
  FOVEA_RETURN_IF_ERROR(
      ValidateLevels(options.itti_centres, "itti_centres", 0));
  FOVEA_RETURN_IF_ERROR(ValidateLevels(options.itti_deltas, "itti_deltas", 1));
  return Validate(options.normalization_options);
}

absl::StatusOr<cv::Mat> ResampleBetweenLevels(const cv::Mat& map, int from,
                                              int to,
                                              const CloudPyramid& pyramid) {
  if (from < 0 || from >= pyramid.size() || to < 0 || to >= pyramid.size()) {
    return absl::InvalidArgumentError(absl::StrCat("levels ", from, " -> ", to,
                                                   " outside the pyramid's ",
                                                   pyramid.size(), " levels"));
  }
  const cv::Size size = LevelSize(pyramid, from);
  if (map.type() != CV_32FC1 || map.size() != size) {
    return absl::InvalidArgumentError(
        absl::StrCat("map to resample must be CV_32FC1 ", size.width, "x",
                     size.height, " (level ", from, ")"));
  }
  cv::Mat out = map;
  for (int l = from; l < to; ++l) {
    cv::Mat next;
    cv::pyrDown(out, next, LevelSize(pyramid, l + 1));
    out = std::move(next);
  }
  for (int l = from; l > to; --l) {
    cv::Mat next;
    cv::pyrUp(out, next, LevelSize(pyramid, l - 1));
    out = std::move(next);
  }
  return from == to ? map.clone() : out;
}

absl::StatusOr<Conspicuity> BuildConspicuityMap(
    const CloudPyramid& pyramid, const LevelFeature& feature,
    const FeaturePyramidOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (pyramid.levels.empty()) {
    return absl::InvalidArgumentError("the cloud pyramid has no levels");
  }
  if (!feature) {
    return absl::InvalidArgumentError("the level feature function is empty");
  }
  return Build(pyramid, feature, options);
}

}  // namespace fovea
