#ifndef FOVEA_CORE_PYRAMID_NORMALIZATION_H_
#define FOVEA_CORE_PYRAMID_NORMALIZATION_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea {

// Map normalisations of thesis section 2.4 (eq. 2.37-2.39). Their own enum
// so core/pyramid does not depend on core/pipeline.
enum class MapNormalization {
  kLin,  // eq. 2.37: divide by the maximum
  kNms,  // eq. 2.38: Itti's N(.), promotes maps with one strong peak
  kNlm,  // eq. 2.39: divide by sqrt(number of near-maximal peaks)
};

struct NormalizationOptions {
  // NMS and NLM: a local maximum counts only if its value, after scaling
  // the map to [0, 1], is above this. [0, 1). (Itti's implementation
  // ignores peaks below 10 % of the map's range, iLab Neuromorphic Vision
  // Toolkit, maxNormalizeStd.)
  float min_peak = 0.1f;
  // NMS and NLM: local maxima closer than this to a higher one are dropped,
  // pixels (Euclidean); 0 keeps them all. >= 0.
  float min_peak_distance = 0.0f;
  // NLM: a local maximum is "near the global maximum" if its value is at
  // least (1 - nlm_range) times the global maximum. [0, 1].
  float nlm_range = 0.1f;
};

// OK, or INVALID_ARGUMENT naming the field that breaks its range.
absl::Status Validate(const NormalizationOptions& options);

struct LocalMaximum {
  // (column, row); for a plateau, its first pixel in scan order.
  cv::Point pixel;
  float value = 0.0f;
};

// Local maxima of a CV_32FC1 map: pixels >= each of their 8 neighbours
// (neighbours outside the map are ignored) with a value > `min_value`.
// A plateau (8-connected pixels of equal value that are all such maxima)
// is ONE maximum, so a flat-topped peak counts once. Then, scanning from
// the highest, a maximum closer than `min_distance` pixels to one already
// kept is dropped (0: keep all). Sorted by decreasing value (ties by scan
// order of `pixel`). Empty map: no maxima.
// Precondition (checked): `map` is empty or CV_32FC1.
std::vector<LocalMaximum> FindLocalMaxima(const cv::Mat& map, float min_value,
                                          float min_distance);

// Normalises a feature map; the input is not modified.
// Input: CV_32FC1, any size (square or not), values finite and >= 0
// (0 = not salient). Output: CV_32FC1 of the same size, values in [0, 1].
//   kLin (eq. 2.37): map / max(map).
//   kNms (eq. 2.38): m = map / max(map) (max is 1), then
//          m * (1 - mean of the OTHER local maxima of m)^2,
//        "other" = every maximum of FindLocalMaxima(m, min_peak,
//        min_peak_distance) but the highest one; a tie with the highest
//        counts as another maximum. No other maximum: factor 1. A map with
//        one strong peak keeps its scale; a map with several equal strong
//        peaks goes to about 0.
//   kNlm (eq. 2.39): m = map / max(map), then m / sqrt(n) with n the
//        number of local maxima of m (same rules) >= 1 - nlm_range; n >= 1
//        because the global maximum counts.
// Every kind: an all-zero map stays all zero; an empty map gives an empty
// map. Errors: INVALID_ARGUMENT for a non-CV_32FC1 map, a negative or
// non-finite value (naming its pixel) or invalid options.
absl::StatusOr<cv::Mat> NormalizeMap(const cv::Mat& map, MapNormalization kind,
                                     const NormalizationOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_PYRAMID_NORMALIZATION_H_
