#ifndef FOVEA_TOOLS_EVAL_TRAINING_SCENES_H_
#define FOVEA_TOOLS_EVAL_TRAINING_SCENES_H_

#include <cstdint>
#include <vector>

#include "core/frame/osd_pcd.h"
#include "core/synth/room.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea::eval {

// The synthetic scenes INC's relation SVM is trained on beside the OSD
// learn scenes (models/README.md): piles (Kinect v1) and stacked piles on
// both sensors, seeds from 1000001 so that the evaluations' scenes (seeds
// from 1) stay held out. fovea-train makes the shipped model from them and
// the scorecard's leave-one-kind-out folds add the same ones.
inline constexpr uint64_t kTrainingSceneSeed = 1000001;

// `piles` piles and `stacked` stacked piles per sensor, in that order.
inline std::vector<LabelledFrame> SyntheticTrainingScenes(int piles,
                                                          int stacked) {
  std::vector<LabelledFrame> scenes;
  for (int k = 0; k < piles; ++k) {
    scenes.push_back(synth::GeneratePile(kTrainingSceneSeed + k).frame);
  }
  for (const synth::RoomSensor sensor :
       {synth::RoomSensor::kKinectV1, synth::RoomSensor::kActiveStereo}) {
    for (int k = 0; k < stacked; ++k) {
      scenes.push_back(
          synth::GenerateStackedPile(kTrainingSceneSeed + k, sensor)
              .scene.frame);
    }
  }
  return scenes;
}

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_TRAINING_SCENES_H_
