// PatchMatch building blocks: the plane xi_p of a pixel (METHOD.md section 3), its transfer between
// views, and the counter-based random numbers that make every sweep deterministic.
#pragma once

#include <cmath>
#include <cstdint>

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Plane d = a x + b y + c in the pixel coordinates of its view [px of disparity].
struct Plane {
  float a = 0.f, b = 0.f, c = 0.f;
  float at(float x, float y) const { return a * x + b * y + c; }
};

/// Plane through disparity d at (x, y) with unit normal n (nz != 0):
/// a = -nx/nz, b = -ny/nz, c = (nx x + ny y + nz d)/nz.
inline Plane planeFromNormal(float x, float y, float d, float nx, float ny, float nz) {
  return Plane{-nx / nz, -ny / nz, (nx * x + ny * y + nz * d) / nz};
}

/// Unit normal of a plane (nz > 0).
inline void normalOf(const Plane& p, float& nx, float& ny, float& nz) {
  const float inv = 1.f / std::sqrt(p.a * p.a + p.b * p.b + 1.f);
  nx = -p.a * inv;
  ny = -p.b * inv;
  nz = inv;
}

/// Transfers a plane between views. A left point (x, y, d) is the right point (x - d, y, d):
/// d = a (x_r + d) + b y + c  =>  d = (a x_r + b y + c) / (1 - a). The inverse uses -a.
inline Plane transferPlane(const Plane& p, bool left_to_right) {
  const float k = left_to_right ? 1.f / (1.f - p.a) : 1.f / (1.f + p.a);
  return Plane{p.a * k, p.b * k, p.c * k};
}

constexpr float kSamePlaneTolerance = 0.01f;  ///< [px]

/// True when two planes have the same slope to 1e-3 px/px in x and y.
inline bool parallel(const Plane& p, const Plane& q) {
  return std::abs(p.a - q.a) < 1e-3f && std::abs(p.b - q.b) < 1e-3f;
}

/// True when two planes agree to kSamePlaneTolerance px at (x, y) and are parallel: evaluating
/// one after the other cannot change the result meaningfully.
inline bool nearlySame(const Plane& p, const Plane& q, float x, float y) {
  return std::abs(p.at(x, y) - q.at(x, y)) < kSamePlaneTolerance && parallel(p, q);
}

/// Counter-based random numbers (splitmix64): deterministic per (seed, stream), so results do not
/// depend on the thread count or the order in which threads reach pixels.
struct Rng {
  uint64_t state;
  explicit Rng(uint64_t seed) : state(seed) {}
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * static_cast<float>((next() >> 40) * (1.0 / 16777216.0));
  }
};

/// Seed of the random stream of one pixel in one step (view 0 = left, 1 = right; iteration -1 =
/// initialisation).
inline uint64_t streamKey(uint64_t seed, int view, int iteration, int pixel) {
  Rng r(seed ^ (static_cast<uint64_t>(view + 1) << 56) ^
        (static_cast<uint64_t>(iteration + 1) << 40) ^ static_cast<uint64_t>(pixel));
  return r.next();
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
