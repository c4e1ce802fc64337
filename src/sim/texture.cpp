// Procedural textures: value noise, fractal noise with footprint fading, road and facade patterns.
#include "lidar_stereo_fusion/sim/texture.h"

#include <algorithm>
#include <cmath>

#include "lidar_stereo_fusion/sim/random.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

/// Quintic fade 6t^5 - 15t^4 + 10t^3 (C2 at lattice points).
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

double lattice(int64_t i, int64_t j, uint64_t seed) {
  return unitFromHash(hashCombine(seed, static_cast<uint64_t>(i), static_cast<uint64_t>(j)));
}

/// Fraction of the interval [x - fp / 2, x + fp / 2] that lies inside [a, b] (a box-filtered
/// indicator; an exact step when fp is 0).
double coverage(double x, double a, double b, double fp) {
  if (fp < 1e-9) return (x >= a && x < b) ? 1.0 : 0.0;
  const double overlap = std::min(x + 0.5 * fp, b) - std::max(x - 0.5 * fp, a);
  return std::clamp(overlap / fp, 0.0, 1.0);
}

/// Coverage of the periodic interval [a, b) + k * period (0 <= a < b <= period).
double periodicCoverage(double x, double a, double b, double period, double fp) {
  const double m = x - period * std::floor(x / period);
  fp = std::min(fp, period);
  return coverage(m, a, b, fp) + coverage(m - period, a, b, fp) + coverage(m + period, a, b, fp);
}

Eigen::Vector3d lerp(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) {
  return a + (b - a) * t;
}

/// Albedo modulated in brightness by fractal noise, with a weaker independent tint per channel.
Eigen::Vector3d noisyAlbedo(const Eigen::Vector3d& albedo, double contrast, double wavelength,
                            int octaves, const Eigen::Vector2d& uv, double fp, uint64_t seed) {
  if (contrast <= 0.0) return albedo;
  const double n = fractalNoise(uv.x(), uv.y(), wavelength, octaves, fp, seed);
  Eigen::Vector3d out;
  for (int c = 0; c < 3; ++c) {
    const double tint = fractalNoise(uv.x(), uv.y(), wavelength, std::min(octaves, 3), fp,
                                     hashCombine(seed, 17 + c));
    out[c] = albedo[c] * std::max(0.0, 1.0 + contrast * (n + 0.1 * tint));
  }
  return out;
}

/// kRoad: asphalt between the edge lines, paving beyond, white markings (box-filtered).
Eigen::Vector3d roadAlbedo(const Material& m, const Eigen::Vector2d& uv, double fp, uint64_t seed) {
  constexpr double kRoadLeft = -5.5, kRoadRight = 4.0;  // [m] across the street
  constexpr double kCentreLine = -0.9, kLineHalfWidth = 0.075, kEdgeHalfWidth = 0.1;
  constexpr double kDashLength = 3.0, kDashPeriod = 9.0;  // [m] along the street
  const double u = uv.x(), v = uv.y();
  if (u < kRoadLeft || u >= kRoadRight) {
    const Eigen::Vector3d paving(0.55, 0.53, 0.50);
    return noisyAlbedo(paving, 0.35, 0.6, m.octaves, uv, fp, hashCombine(seed, 1));
  }
  const Eigen::Vector3d asphalt =
      noisyAlbedo(m.albedo, m.contrast, m.wavelength_m, m.octaves, uv, fp, seed);
  const double centre =
      coverage(u, kCentreLine - kLineHalfWidth, kCentreLine + kLineHalfWidth, fp) *
      periodicCoverage(v, 0.0, kDashLength, kDashPeriod, fp);
  const double edges =
      coverage(u, kRoadLeft + 0.2 - kEdgeHalfWidth, kRoadLeft + 0.2 + kEdgeHalfWidth, fp) +
      coverage(u, kRoadRight - 0.2 - kEdgeHalfWidth, kRoadRight - 0.2 + kEdgeHalfWidth, fp);
  const Eigen::Vector3d paint(0.80, 0.80, 0.78);
  return lerp(asphalt, paint, std::clamp(centre + edges, 0.0, 1.0));
}

/// kFacade: wall noise, a darker plinth, and a grid of windows from the second floor up.
Eigen::Vector3d facadeAlbedo(const Material& m, const Eigen::Vector2d& uv, double fp,
                             uint64_t seed) {
  constexpr double kBay = 3.0, kFloor = 3.2;                      // [m] window grid
  constexpr double kWindowLeft = 0.9, kWindowRight = 2.1;         // [m] within a bay
  constexpr double kSillHeight = 1.0, kLintelHeight = 2.5;        // [m] within a floor
  constexpr double kFirstWindowFloor = 1.0, kPlinthHeight = 0.6;  // [m]
  const double u = uv.x(), height = uv.y();
  Eigen::Vector3d wall = noisyAlbedo(m.albedo, m.contrast, m.wavelength_m, m.octaves, uv, fp, seed);
  wall *= 1.0 - 0.4 * coverage(height, -1e9, kPlinthHeight, fp);
  const double window = periodicCoverage(u, kWindowLeft, kWindowRight, kBay, fp) *
                        periodicCoverage(height, kSillHeight, kLintelHeight, kFloor, fp) *
                        coverage(height, kFirstWindowFloor * kFloor, 1e9, fp);
  const Eigen::Vector3d glass =
      noisyAlbedo(Eigen::Vector3d(0.10, 0.12, 0.16), 0.6, 0.4, 4, uv, fp, hashCombine(seed, 2));
  return lerp(wall, glass, std::clamp(window, 0.0, 1.0));
}

}  // namespace

double valueNoise(double u, double v, uint64_t seed) {
  const double fu = std::floor(u), fv = std::floor(v);
  const auto i = static_cast<int64_t>(fu), j = static_cast<int64_t>(fv);
  const double tu = fade(u - fu), tv = fade(v - fv);
  const double a = lattice(i, j, seed), b = lattice(i + 1, j, seed);
  const double c = lattice(i, j + 1, seed), d = lattice(i + 1, j + 1, seed);
  return (a + (b - a) * tu) + ((c + (d - c) * tu) - (a + (b - a) * tu)) * tv;
}

double fractalNoise(double u, double v, double wavelength_m, int octaves, double footprint_m,
                    uint64_t seed) {
  double sum = 0.0, norm = 0.0, amplitude = 1.0, wavelength = wavelength_m;
  for (int k = 0; k < octaves; ++k) {
    norm += amplitude * amplitude;
    // Fade: 1 when the wavelength is at least 2 footprints, 0 at 1 footprint or less.
    const double weight =
        footprint_m > 0.0 ? std::clamp(wavelength / footprint_m - 1.0, 0.0, 1.0) : 1.0;
    if (weight > 0.0) {
      const uint64_t octave_seed = hashCombine(seed, static_cast<uint64_t>(k));
      // Offset each octave so lattice points of different octaves do not line up.
      const double offset = 0.37 * k;
      const double n = valueNoise(u / wavelength + offset, v / wavelength - offset, octave_seed);
      sum += weight * amplitude * 2.0 * (n - 0.5);
    }
    amplitude *= 0.7;
    wavelength *= 0.5;
  }
  return norm > 0.0 ? 1.6 * sum / std::sqrt(norm) : 0.0;
}

Eigen::Vector3d texturedAlbedo(const Material& material, const Eigen::Vector2d& uv,
                               double footprint_m, uint64_t seed) {
  Eigen::Vector3d albedo = material.albedo;  // kUniform
  switch (material.pattern) {
    case Pattern::kUniform:
      break;
    case Pattern::kNoise:
      albedo = noisyAlbedo(material.albedo, material.contrast, material.wavelength_m,
                           material.octaves, uv, footprint_m, seed);
      break;
    case Pattern::kRoad:
      albedo = roadAlbedo(material, uv, footprint_m, seed);
      break;
    case Pattern::kFacade:
      albedo = facadeAlbedo(material, uv, footprint_m, seed);
      break;
  }
  return albedo.cwiseMax(0.0).cwiseMin(1.0);
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
