#ifndef FOVEA_CORE_SYNTH_OSD_CROP_H_
#define FOVEA_CORE_SYNTH_OSD_CROP_H_

#include <cstdint>

#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The crop the OSD scenes were published with (shared/data/README.md: "the
// floor, walls and far end of the table were cropped to NaN"), made on a
// rendered scene: every pixel that is not an object's loses its depth (NaN)
// and its label (0) where its world point lies beyond world y = far_y
// (metres; +y is away from the camera in the generators' scenes) or is not
// on the table at all (floor, walls, furniture: background labels 2-9).
// Objects keep every pixel: those behind far_y now rest on a table the
// camera does not see, as on a real table that books and boxes cover.
void CropLikeOsd(const SceneSpec& spec, float far_y, SynthScene& scene);

// A stacked pile (GenerateStackedPile(seed, sensor)) with OSD's crop at the
// pile's middle: the table is seen only in front of the mean y of the
// objects' centres (plus a draw in [-3, 6] cm from a stream of `seed`), so
// that the back half of the pile projects outside the hull of the visible
// table, the case of OSD's complex piles. frame.name "stack-crop-<seed>"
// (Kinect v1) or "stack-crop-as-<seed>".
StackedPile GenerateCroppedPile(uint64_t seed, RoomSensor sensor);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_OSD_CROP_H_
