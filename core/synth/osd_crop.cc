#include "core/synth/osd_crop.h"

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/base/strings.h"
#include "core/frame/osd_pcd.h"
#include "core/synth/random.h"

namespace fovea::synth {
namespace {

// Stream id mixed into the seed for the crop's draw ("crop").
constexpr uint64_t kCropStream = 0x63726f70ULL;
// Where the crop falls against the objects' mean y, metres.
constexpr float kCropShiftMin = -0.03f, kCropShiftMax = 0.06f;

}  // namespace

void CropLikeOsd(const SceneSpec& spec, float far_y, SynthScene& scene) {
  LabelledFrame& f = scene.frame;
  const Intrinsics& k = f.frame.intrinsics;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < f.frame.depth.rows; ++v) {
    float* depth = f.frame.depth.ptr<float>(v);
    int* label = f.labels.ptr<int>(v);
    for (int u = 0; u < f.frame.depth.cols; ++u) {
      if (ObjectId(label[u]) != 0) continue;
      const float z = depth[u];
      bool crop = label[u] != kSupportTableLabel && label[u] != 0;
      if (!crop && !std::isnan(z)) {
        const Eigen::Vector3f camera(static_cast<float>((u - k.cx) / k.fx) * z,
                                     static_cast<float>((v - k.cy) / k.fy) * z,
                                     z);
        crop = (spec.camera_pose * camera).y() > far_y;
      }
      if (crop) {
        depth[u] = nan;
        label[u] = 0;
      }
    }
  }
}

StackedPile GenerateCroppedPile(uint64_t seed, RoomSensor sensor) {
  StackedPile pile = GenerateStackedPile(seed, sensor);
  float mean_y = 0.0f;
  for (const Primitive& p : pile.spec.objects)
    mean_y += p.pose.translation().y();
  if (!pile.spec.objects.empty()) mean_y /= pile.spec.objects.size();
  Random rng(seed ^ kCropStream);
  CropLikeOsd(pile.spec, mean_y + rng.Uniform(kCropShiftMin, kCropShiftMax),
              pile.scene);
  pile.scene.frame.name =
      absl::StrCat("stack-crop-", AbslView(RoomSensorTag(sensor)), seed);
  return pile;
}

}  // namespace fovea::synth
