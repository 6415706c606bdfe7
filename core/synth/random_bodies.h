#ifndef FOVEA_CORE_SYNTH_RANDOM_BODIES_H_
#define FOVEA_CORE_SYNTH_RANDOM_BODIES_H_

// The objects of RandomSceneSpec before they are posed (random_scene.cc):
// shapes, sizes and colours. Also HSV colours for the other generators.

#include <Eigen/Core>
#include <cmath>

#include "core/synth/random.h"
#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The smallest box half size and cylinder half height, metres (also the
// least of what is stacked on a box).
inline constexpr float kBoxHalfMin = 0.015f;
inline constexpr float kCylinderHalfHeightMin = 0.025f;

// A shape with its size and colour, before it is posed.
struct Body {
  Shape shape = Shape::kBox;
  Eigen::Vector3f half_extents =
      Eigen::Vector3f::Constant(0.05f);  // box; z for cyl/cone
  float radius = 0.05f;
  bool lying = false;         // cylinder on its side
  float lean = 0.0f;          // box tilted about its local y axis, radians
  float thickness = 0.005f;   // bowl and cup walls
  float floor_height = 0.0f;  // a bowl's inner floor above its foot
  Eigen::Vector3f rgb = Eigen::Vector3f::Constant(0.5f);

  float Height() const {
    switch (shape) {
      case Shape::kBox:
        return 2.0f * (half_extents.x() * std::sin(lean) +
                       half_extents.z() * std::cos(lean));
      case Shape::kCone:
      case Shape::kBowl:
      case Shape::kCup:
        return 2.0f * half_extents.z();
      case Shape::kCylinder:
        return lying ? 2.0f * radius : 2.0f * half_extents.z();
      case Shape::kSphere:
        return 2.0f * radius;
    }
    return 0.0f;
  }
};

// Hue, saturation and value in [0, 1] as RGB in [0, 1].
Eigen::Vector3f HsvToRgb(float h, float s, float v);

// An object's colour: dark (value below 0.09) with `dark_probability`,
// else saturated, bright enough and clear of `table_rgb`.
Eigen::Vector3f RandomAlbedo(const Eigen::Vector3f& table_rgb,
                             float dark_probability, Random& rng);

// A body of the household mix (boxes, books, cylinders, bowls, cups,
// spheres, cones), or of the basic one (box, cylinder, sphere, cone).
Body RandomHouseholdBody(const Eigen::Vector3f& rgb, Random& rng);
Body RandomBody(const Eigen::Vector3f& rgb, Random& rng);

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_RANDOM_BODIES_H_
