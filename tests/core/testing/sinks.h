#ifndef FOVEA_TESTS_CORE_TESTING_SINKS_H_
#define FOVEA_TESTS_CORE_TESTING_SINKS_H_

// Sinks for core tests of the segmentations.

#include <opencv2/core.hpp>
#include <vector>

#include "core/pipeline/segment.h"

namespace fovea::testing {

// Sinks that keep each object's mask in `masks`, in the order they come.
inline SegmentSinks CollectMasks(std::vector<cv::Mat>& masks) {
  SegmentSinks sinks;
  sinks.object = [&masks](SegmentedObject object) {
    masks.push_back(object.mask);
    return absl::OkStatus();
  };
  return sinks;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_TESTING_SINKS_H_
