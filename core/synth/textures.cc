#include "core/synth/textures.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/base/check.h"
#include "core/synth/random.h"
#include "core/synth/random_bodies.h"

namespace fovea::synth {
namespace {

// Hash of an integer cell to [0, 1).
float CellHash(int x, int y, int z) {
  uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(x)) * 0x9e3779b1ULL ^
               static_cast<uint64_t>(static_cast<uint32_t>(y)) * 0x85ebca77ULL ^
               static_cast<uint64_t>(static_cast<uint32_t>(z)) * 0xc2b2ae3dULL;
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 32;
  return static_cast<float>(h & 0xffffff) / 16777216.0f;
}

// Trilinear value noise of cells `cell` metres wide, [0, 1).
float ValueNoise(const Eigen::Vector3f& p, float cell) {
  const Eigen::Vector3f q = p / cell;
  const int x = static_cast<int>(std::floor(q.x()));
  const int y = static_cast<int>(std::floor(q.y()));
  const int z = static_cast<int>(std::floor(q.z()));
  const float fx = q.x() - x, fy = q.y() - y, fz = q.z() - z;
  float value = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const int dx = i & 1, dy = (i >> 1) & 1, dz = i >> 2;
    const float w =
        (dx ? fx : 1.0f - fx) * (dy ? fy : 1.0f - fy) * (dz ? fz : 1.0f - fz);
    value += w * CellHash(x + dx, y + dy, z + dz);
  }
  return value;
}

}  // namespace

// The factor a texture multiplies the albedo by at world point p.
float TextureFactor(Texture texture, const Eigen::Vector3f& p) {
  constexpr float kTwoPi = 6.2831853f;
  switch (texture) {
    case Texture::kFlat:
      return 1.0f;
    case Texture::kWood: {
      // Grain along world x: stripes across y whose phase wanders slowly.
      const float wander = 3.0f * ValueNoise(p, 0.15f);
      const float grain =
          0.5f + 0.5f * std::sin(kTwoPi * (p.y() / 0.013f + wander));
      return 0.88f + 0.12f * grain + 0.08f * (ValueNoise(p, 0.03f) - 0.5f);
    }
    case Texture::kCarpet:
      return 0.75f +
             0.5f * CellHash(static_cast<int>(std::floor(p.x() / 0.004f)),
                             static_cast<int>(std::floor(p.y() / 0.004f)),
                             static_cast<int>(std::floor(p.z() / 0.004f)));
    case Texture::kPaint:
      return 0.95f + 0.1f * ValueNoise(p, 0.2f);
    case Texture::kPrint:  // a colour, not a factor: PrintWeight
      return 1.0f;
  }
  return 1.0f;
}

// kPrint: the weight of the print colour at point `local` of the
// primitive's frame: blobs where smooth noise of 4 cm cells rises above a
// level that itself wanders over 12 cm, so that one face of a box is
// mostly print and another mostly plain, as packaging's faces differ; the
// blobs' edges are a few millimetres wide (a print's, sharper than paint).
float PrintWeight(const Eigen::Vector3f& local) {
  const float level = 0.3f + 0.5f * ValueNoise(local, 0.12f);
  const float n = ValueNoise(local, 0.04f);
  return std::clamp((n - level) / 0.04f, 0.0f, 1.0f);
}

void AddPrints(uint64_t seed, float probability, SceneSpec& spec) {
  FOVEA_CHECK(probability >= 0.0f && probability <= 1.0f);
  // A stream of its own: the spec's draws are not disturbed.
  Random rng(seed ^ 0x7072696e74735eedULL);
  std::vector<std::optional<Eigen::Vector3f>> print(spec.objects.size());
  for (std::optional<Eigen::Vector3f>& colour : print) {
    if (!rng.Bernoulli(probability)) continue;
    const int look = rng.UniformInt(0, 3);
    if (look == 0) {
      colour = Eigen::Vector3f(0.95f, 0.95f, 0.93f);  // white
    } else if (look == 1) {
      colour = Eigen::Vector3f(0.08f, 0.08f, 0.1f);  // black
    } else {
      colour = HsvToRgb(rng.Uniform(0.0f, 1.0f), 0.8f, 0.85f);
    }
  }
  const auto apply = [](const std::optional<Eigen::Vector3f>& colour,
                        Primitive& p) {
    if (!colour) return;
    p.texture = Texture::kPrint;
    p.print_rgb = *colour;
  };
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    apply(print[k], spec.objects[k]);
  }
  for (ObjectPart& part : spec.object_parts) {
    apply(print[static_cast<size_t>(part.object)], part.primitive);
  }
}

}  // namespace fovea::synth
