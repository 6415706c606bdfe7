#ifndef FOVEA_CORE_SYNTH_RANDOM_H_
#define FOVEA_CORE_SYNTH_RANDOM_H_

#include <cmath>
#include <cstdint>
#include <random>

namespace fovea::synth {

// A portable random source for core/synth. std::mt19937_64 is specified
// bit-exactly by the standard, but std::uniform_real_distribution and
// std::normal_distribution are not, so the distributions are computed here
// from the engine's bits: the same seed gives the same stream with every
// standard library.
class Random {
 public:
  explicit Random(uint64_t seed) : engine_(Mix(seed)) {}

  // Uniform in [0, 1), 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Uniform in [lo, hi).
  float Uniform(float lo, float hi) {
    return lo + static_cast<float>(Uniform()) * (hi - lo);
  }
  // Uniform integer in [lo, hi], hi >= lo (bias < 2^-53 for small ranges).
  int UniformInt(int lo, int hi) {
    const int n = hi - lo + 1;
    const int k = static_cast<int>(Uniform() * n);
    return lo + (k < n ? k : n - 1);
  }
  bool Bernoulli(double p) { return Uniform() < p; }

  // Standard normal (Marsaglia's polar method; each pair is used fully).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double x, y, s;
    do {
      x = 2.0 * Uniform() - 1.0;
      y = 2.0 * Uniform() - 1.0;
      s = x * x + y * y;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = y * f;
    has_spare_ = true;
    return x * f;
  }

  // Approximately standard normal, for bulk noise where the tails do not
  // matter (image colour): the Irwin-Hall sum of four 8-bit uniforms,
  // scaled to unit variance, |value| <= 2 sqrt(3) (to 3%). One engine draw
  // gives two values.
  float ApproxNormal() {
    if (approx_bits_left_ == 0) {
      approx_bits_ = engine_();
      approx_bits_left_ = 2;
    }
    const uint32_t word = static_cast<uint32_t>(approx_bits_);
    approx_bits_ >>= 32;
    --approx_bits_left_;
    const uint32_t sum = (word & 0xff) + ((word >> 8) & 0xff) +
                         ((word >> 16) & 0xff) + (word >> 24);
    // Mean 4 * 127.5, variance 4 * (256^2 - 1) / 12 = 21845.
    constexpr float kInvSigma = 0.0067658f;  // 1 / sqrt(21845)
    return (static_cast<float>(sum) - 510.0f) * kInvSigma;
  }

 private:
  // SplitMix64 finaliser: nearby seeds (1, 2, 3...) give unrelated states.
  static uint64_t Mix(uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
  uint64_t approx_bits_ = 0;
  int approx_bits_left_ = 0;
};

}  // namespace fovea::synth

#endif  // FOVEA_CORE_SYNTH_RANDOM_H_
