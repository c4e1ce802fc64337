// Materials and deterministic procedural textures of the synthetic street scene.
//
// Textures are functions of surface coordinates in metres, so that both cameras see the same
// pattern on a surface (stereo can match it) and the LiDAR sees the same reflectivity. Noise
// octaves finer than the pixel footprint are faded to their mean (a cheap pre-filter), so distant
// or grazing surfaces do not alias differently in the two views.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace lidar_stereo_fusion {
namespace sim {

/// How a material's albedo varies over its surface.
enum class Pattern {
  kUniform,  ///< constant albedo: no texture at all (the "stereo fails here" material)
  kNoise,    ///< fractal value noise on the albedo's brightness
  kRoad,     ///< street: asphalt for -5.5 <= u < 4.0 [m] with a dashed centre line at u = -0.9 and
             ///< solid edge lines, lighter paving beyond (u across, v along the street)
  kFacade,   ///< wall noise with a grid of dark windows (u along the wall, v = height [m])
};

/// Surface appearance for the cameras and the LiDAR.
struct Material {
  Eigen::Vector3d albedo{0.5, 0.5, 0.5};  ///< linear RGB reflectance, each in [0, 1]
  Pattern pattern = Pattern::kNoise;
  double contrast = 0.3;            ///< relative brightness amplitude of the texture (0 = none)
  double wavelength_m = 0.5;        ///< coarsest noise wavelength [m]; octaves halve it
  int octaves = 5;                  ///< noise octaves
  double lidar_reflectivity = 0.3;  ///< LiDAR intensity at normal incidence, in [0, 1]
  bool low_texture = false;         ///< marks the region where stereo alone is expected to fail
};

/// Smooth value noise in [0, 1] on the unit lattice (quintic interpolation of hashed corners).
double valueNoise(double u, double v, uint64_t seed);

/// Fractal noise in about [-1, 1] (mean 0): `octaves` octaves of valueNoise from `wavelength_m`
/// down, each half the previous wavelength and amplitude. Octaves whose wavelength is below
/// 2 * footprint_m [m] are faded out (fully gone at 1x the footprint).
double fractalNoise(double u, double v, double wavelength_m, int octaves, double footprint_m,
                    uint64_t seed);

/// Textured albedo (linear RGB, clamped to [0, 1]) of `material` at surface coordinates `uv` [m];
/// `footprint_m` is the size of one pixel on the surface [m]; `seed` separates the noise of
/// different surfaces.
Eigen::Vector3d texturedAlbedo(const Material& material, const Eigen::Vector2d& uv,
                               double footprint_m, uint64_t seed);

}  // namespace sim
}  // namespace lidar_stereo_fusion
