// What rests on another object is an object: SegmentIncremental, with the
// shipped models, on synthetic stacked piles (boxes on books and boxes,
// cups in bowls, objects in an open box).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/synth/stacked_scene.h"
#include "tests/core/testing/models.h"
#include "tests/core/testing/sinks.h"

namespace fovea {
namespace {

const LoadedModels* Models() { return testing::ShippedModels(); }

// The best F of any mask against `object` (CV_8UC1, non-zero on it).
double BestF(const std::vector<cv::Mat>& masks, const cv::Mat& object) {
  const double size = cv::countNonZero(object);
  double best = 0.0;
  for (const cv::Mat& mask : masks) {
    const double both = cv::countNonZero(mask & object);
    best = std::max(best, 2.0 * both / (size + cv::countNonZero(mask)));
  }
  return best;
}

TEST(StackedSegmentTest, ObjectsRestingOnOtherObjectsGetMasksOfTheirOwn) {
  ASSERT_NE(Models(), nullptr) << "the shipped models do not load";
  int resting = 0, found = 0;
  for (const synth::RoomSensor sensor :
       {synth::RoomSensor::kKinectV1, synth::RoomSensor::kActiveStereo}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      const synth::StackedPile pile = synth::GenerateStackedPile(seed, sensor);
      std::vector<cv::Mat> masks;
      const absl::Status status =
          RunSegmentIncremental(pile.scene.frame.frame, IncrementalOptions{},
                                &*Models()->inc, testing::CollectMasks(masks))
              .status();
      ASSERT_TRUE(status.ok()) << pile.scene.frame.name << ": " << status;
      for (size_t k = 0; k < pile.rests_on.size(); ++k) {
        if (pile.rests_on[k] < 0) continue;
        const cv::Mat object =
            pile.scene.frame.labels == static_cast<int>(10 * (k + 2));
        if (cv::countNonZero(object) < 200) continue;  // hardly in view
        ++resting;
        const double f = BestF(masks, object);
        found += f >= 0.5;
        if (f < 0.5) {
          ADD_FAILURE() << pile.scene.frame.name << ": object " << k << " ("
                        << synth::StackedKindName(pile.kinds[k]) << " on "
                        << synth::StackedKindName(pile.kinds[pile.rests_on[k]])
                        << ") best F " << f;
        }
      }
    }
  }
  EXPECT_GE(resting, 15);
  EXPECT_EQ(found, resting);
}

}  // namespace
}  // namespace fovea
