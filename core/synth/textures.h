#ifndef FOVEA_CORE_SYNTH_TEXTURES_H_
#define FOVEA_CORE_SYNTH_TEXTURES_H_

#include <Eigen/Core>
#include <cstdint>

#include "core/synth/synth_scene.h"

namespace fovea::synth {

// The surface textures of synth_scene.h's Texture, as the renderer applies
// them, and the prints household objects carry.

// The factor kWood, kCarpet and kPaint multiply the albedo by at world
// point `p` (metres); 1 for kFlat and kPrint.
float TextureFactor(Texture texture, const Eigen::Vector3f& p);

// kPrint: the weight in [0, 1] of Primitive::print_rgb at point `local` of
// the primitive's own frame (metres).
float PrintWeight(const Eigen::Vector3f& local);

// Prints on household objects, as real packaging, labels and mugs carry
// them (docs/realism.md: with flat albedos, two surfaces of one synthetic
// object were nearly always of one colour, colour similarity median 0.9995
// against OSD's 0.868). Each object of `spec` (its parts alike) gets
// Texture::kPrint with probability `probability` and a print colour: white,
// black or a saturated hue. Drawn from a stream of its own derived from
// `seed`, so that the scene's geometry is the one without prints.
// Precondition (checked): probability in [0, 1].
void AddPrints(uint64_t seed, float probability, SceneSpec& spec);

// The share of a pile's, stacked pile's or room's objects that carry prints
// (AddPrints).
inline constexpr float kPrintedObjectShare = 0.7f;

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_TEXTURES_H_
