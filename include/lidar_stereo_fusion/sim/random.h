// Deterministic, platform-independent random numbers for the synthetic scene generator.
//
// The generator must give bit-identical output for a seed on every machine and with any number of
// threads, so it uses no std:: distributions (their algorithms are implementation-defined) and no
// shared sequential state: every random value is a hash of (seed, what, where).
#pragma once

#include <cstdint>

namespace lidar_stereo_fusion {
namespace sim {

/// SplitMix64 finaliser: a well-mixed 64-bit hash of `x`.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Hash of an ordered pair.
inline uint64_t hashCombine(uint64_t a, uint64_t b) { return mix64(a ^ mix64(b)); }

/// Hash of an ordered triple.
inline uint64_t hashCombine(uint64_t a, uint64_t b, uint64_t c) {
  return hashCombine(hashCombine(a, b), c);
}

/// Uniform double in [0, 1) from the top 53 bits of a hash.
inline double unitFromHash(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// A small sequential generator (SplitMix64) for the few draws made while building a scene.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() { return mix64(state_++); }
  /// Uniform in [0, 1).
  double uniform() { return unitFromHash(next()); }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal (Box-Muller on two uniforms).
  double normal();

 private:
  uint64_t state_;
};

/// Standard normal value from two independent hashes (Box-Muller), for order-free noise.
double normalFromHashes(uint64_t h1, uint64_t h2);

}  // namespace sim
}  // namespace lidar_stereo_fusion
