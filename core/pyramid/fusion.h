#ifndef FOVEA_CORE_PYRAMID_FUSION_H_
#define FOVEA_CORE_PYRAMID_FUSION_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"

namespace fovea {

// How channel (conspicuity) maps become the master map (thesis
// eq. 2.42-2.44). Its own enum so core/pyramid does not depend on
// core/pipeline.
enum class ChannelFusion {
  kSum,  // eq. 2.42-2.43: weighted sum, weights renormalised to sum to 1
  kMax,  // eq. 2.44: pixel-wise maximum
};

// Fuses channel maps into the master map.
// Input: one or more CV_32FC1 maps of the same size (typically in [0, 1]),
// and one weight per map, each finite and >= 0, at least one > 0.
//   kSum: sum_i (w_i / sum_j w_j) map_i. Maps in [0, 1] give a map in
//         [0, 1]; the result is not rescaled.
//   kMax: max_i (w_i / max_j w_j) map_i. With equal weights this is the
//         plain pixel-wise maximum of eq. 2.44; unequal weights scale each
//         channel relative to the most heavily weighted one (a weight of
//         0 drops a channel).
// Output: CV_32FC1 of the maps' size. Errors: INVALID_ARGUMENT for no
// maps, a weight count that differs from the map count, a negative or
// non-finite weight, all weights 0, an empty or non-CV_32FC1 map, or maps
// of different sizes (the message names the map's index).
absl::StatusOr<cv::Mat> FuseChannels(const std::vector<cv::Mat>& maps,
                                     const std::vector<float>& weights,
                                     ChannelFusion fusion);

}  // namespace fovea

#endif  // FOVEA_CORE_PYRAMID_FUSION_H_
