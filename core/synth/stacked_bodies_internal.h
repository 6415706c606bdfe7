#ifndef FOVEA_CORE_SYNTH_STACKED_BODIES_INTERNAL_H_
#define FOVEA_CORE_SYNTH_STACKED_BODIES_INTERNAL_H_

// What the pile bodies' makers share: stacked_bodies.cc (the default
// kinds) and clutter_bodies.cc (StackedPileOptions::more_kinds). Not for
// use outside core/synth.

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <optional>

#include "core/synth/footprint.h"
#include "core/synth/random.h"
#include "core/synth/stacked_bodies.h"

namespace fovea::synth::pile_internal {

inline constexpr float kPi = 3.14159265358979f;
inline constexpr float kSlate[3] = {0.24f, 0.25f, 0.28f};

// Colours are jittered by this much per channel and kept this far (RGB
// distance) from the table.
inline constexpr float kColourJitter = 0.04f;
inline constexpr float kMinDistanceToTable = 0.15f;
inline constexpr int kColourAttempts = 8;

// A colour of `palette`, jittered, kept away from the table's.
template <size_t N>
inline Eigen::Vector3f Pick(const float (&palette)[N][3],
                            const Eigen::Vector3f& table_rgb, Random& rng) {
  Eigen::Vector3f rgb;
  for (int attempt = 0; attempt < kColourAttempts; ++attempt) {
    const float* c = palette[rng.UniformInt(0, static_cast<int>(N) - 1)];
    rgb = Eigen::Vector3f(c[0], c[1], c[2]) +
          Eigen::Vector3f(rng.Uniform(-kColourJitter, kColourJitter),
                          rng.Uniform(-kColourJitter, kColourJitter),
                          rng.Uniform(-kColourJitter, kColourJitter));
    rgb = rgb.cwiseMax(0.0f).cwiseMin(1.0f);
    if ((rgb - table_rgb).norm() >= kMinDistanceToTable) break;
  }
  return rgb;
}

inline Eigen::Vector3f Rgb(const float (&c)[3]) { return {c[0], c[1], c[2]}; }

inline Footprint Rect(const Eigen::Vector2f& centre,
                      const Eigen::Vector2f& half, float z_min, float z_max) {
  Footprint f;
  f.is_circle = false;
  f.centre = centre;
  f.half = half;
  f.z_min = z_min;
  f.z_max = z_max;
  return f;
}

inline Footprint Disc(float radius, float z_min, float z_max) {
  Footprint f;
  f.radius = radius;
  f.z_min = z_min;
  f.z_max = z_max;
  return f;
}

// Uniform in [lo, min(hi, cap)], or nullopt when cap < lo.
inline std::optional<float> Capped(float lo, float hi, float cap, Random& rng) {
  if (cap < lo) return std::nullopt;
  return rng.Uniform(lo, std::min(hi, cap));
}

// A box-shaped body (book, box, tablet): its solid, hull and top.
inline void SetBoxVolumes(const Eigen::Vector3f& half, PileBody& body) {
  const float height = 2.0f * half.z();
  body.hull = Rect(Eigen::Vector2f::Zero(), half.head<2>(), 0.0f, height);
  body.solids = {body.hull};
  body.top = Rect(Eigen::Vector2f::Zero(), half.head<2>(), height, height);
}

// The bodies of StackedPileOptions::more_kinds (clutter_bodies.cc), as
// MakePileBody's (stacked_bodies.h).
std::optional<PileBody> MakeDrill(float room, const Eigen::Vector3f& table_rgb,
                                  Random& rng);
std::optional<PileBody> MakeBanana(float room, Random& rng);
std::optional<PileBody> MakePen(float room, const Eigen::Vector3f& table_rgb,
                                Random& rng);
std::optional<PileBody> MakePart(float room, const Eigen::Vector3f& table_rgb,
                                 Random& rng);

}  // namespace fovea::synth::pile_internal

#endif  // FOVEA_CORE_SYNTH_STACKED_BODIES_INTERNAL_H_
