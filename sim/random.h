// Seeded, platform-independent random numbers for the simulator (noise, textures).
// std::normal_distribution differs between standard libraries; these do not.
#pragma once

#include <cmath>
#include <cstdint>

namespace sim {

// SplitMix64 (Steele, Lea, Flood 2014): a tiny generator with a 64-bit state.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  // Standard normal by the Box–Muller transform (one value per call, the pair's twin discarded
  // so that the sequence depends only on the call count).
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return BoxMuller(u1, u2);
  }
  // The transform itself: u1 in (0, 1], u2 in [0, 1), drawn in that order (noise.cc's fast path
  // draws them itself and calls this where it needs the exact value).
  static double BoxMuller(double u1, double u2) {
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  uint64_t state_;
};

// Derives an independent stream seed from a base seed and up to three indices.
inline uint64_t DeriveSeed(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  SplitMix64 g(seed ^ (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xC2B2AE3D27D4EB4Full) ^
               (c * 0x165667B19E3779F9ull));
  g.Next();
  return g.Next();
}

}  // namespace sim
