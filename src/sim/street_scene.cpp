// The synthetic street scene: buildings, road, cars, a dark van, poles, sign and billboard.
#include "lidar_stereo_fusion/sim/street_scene.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "lidar_stereo_fusion/sim/random.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// Rotation about the street frame's y axis (down); positive yaw turns +z towards +x.
Eigen::Matrix3d yawRotation(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

Material makeMaterial(const Eigen::Vector3d& albedo, Pattern pattern, double contrast,
                      double wavelength_m, double reflectivity) {
  Material m;
  m.albedo = albedo;
  m.pattern = pattern;
  m.contrast = contrast;
  m.wavelength_m = wavelength_m;
  m.lidar_reflectivity = reflectivity;
  return m;
}

/// Materials of the street, by role.
struct Palette {
  int road, pole, sign, billboard, glass, tyre, van;
  std::vector<int> facades, paints;
};

Palette addPalette(Scene& scene) {
  Palette p;
  Material road = makeMaterial({0.30, 0.30, 0.31}, Pattern::kRoad, 0.45, 0.8, 0.15);
  road.octaves = 7;
  p.road = scene.addMaterial(road);
  for (const Eigen::Vector3d& albedo :
       {Eigen::Vector3d(0.66, 0.55, 0.43), Eigen::Vector3d(0.58, 0.34, 0.27),
        Eigen::Vector3d(0.70, 0.70, 0.66), Eigen::Vector3d(0.46, 0.51, 0.57)}) {
    Material facade = makeMaterial(albedo, Pattern::kFacade, 0.35, 0.7, 0.4);
    facade.octaves = 7;
    p.facades.push_back(scene.addMaterial(facade));
  }
  for (const Eigen::Vector3d& albedo :
       {Eigen::Vector3d(0.60, 0.10, 0.08), Eigen::Vector3d(0.12, 0.22, 0.55),
        Eigen::Vector3d(0.62, 0.62, 0.64), Eigen::Vector3d(0.82, 0.82, 0.80),
        Eigen::Vector3d(0.16, 0.38, 0.22)}) {
    p.paints.push_back(scene.addMaterial(makeMaterial(albedo, Pattern::kNoise, 0.3, 0.5, 0.5)));
  }
  p.glass = scene.addMaterial(makeMaterial({0.12, 0.14, 0.18}, Pattern::kNoise, 0.35, 0.4, 0.1));
  p.tyre = scene.addMaterial(makeMaterial({0.06, 0.06, 0.06}, Pattern::kNoise, 0.4, 0.2, 0.05));
  p.pole = scene.addMaterial(makeMaterial({0.42, 0.44, 0.47}, Pattern::kNoise, 0.4, 0.2, 0.6));
  p.sign = scene.addMaterial(makeMaterial({0.70, 0.16, 0.12}, Pattern::kNoise, 0.3, 0.3, 0.9));
  p.billboard = scene.addMaterial(makeMaterial({0.80, 0.72, 0.30}, Pattern::kNoise, 0.7, 0.7, 0.5));
  // The dark van: one flat colour, no texture at all. Stereo cannot match inside it.
  Material van = makeMaterial({0.05, 0.05, 0.055}, Pattern::kUniform, 0.0, 1.0, 0.08);
  van.low_texture = true;
  p.van = scene.addMaterial(van);
  return p;
}

/// Adds scene objects with heights measured above the ground.
class StreetBuilder {
 public:
  StreetBuilder(Scene& scene, const StreetLayout& layout)
      : scene_(scene), ground_y_(layout.camera_height), rng_(hashCombine(layout.seed, 0x57ee7)) {}

  double jitter(double amplitude) { return rng_.uniform(-amplitude, amplitude); }

  /// Box with footprint centre (x, z) [m], size across x / along z, vertical extent
  /// [bottom, top] above the ground [m], turned by `yaw` [rad], optionally tilted by `pitch`.
  void box(double x, double z, double width, double length, double bottom, double top, double yaw,
           int material, double pitch = 0.0) {
    const Eigen::Vector3d centre(x, ground_y_ - 0.5 * (bottom + top), z);
    const Eigen::Vector3d half(0.5 * width, 0.5 * (top - bottom), 0.5 * length);
    const Eigen::Matrix3d rotation =
        yawRotation(yaw) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
    scene_.addBox(centre, half, rotation, material);
  }

  void building(double x0, double x1, double z0, double z1, double height, int material) {
    box(0.5 * (x0 + x1), 0.5 * (z0 + z1), x1 - x0, z1 - z0, 0.0, height, 0.0, material);
  }

  /// A car: body, cabin and four wheels, centred at (x, z), heading `yaw`.
  void car(double x, double z, double yaw, int paint, const Palette& p) {
    scene_.beginGroup();
    const Eigen::Matrix3d r = yawRotation(yaw);
    auto at = [&](double lx, double lz) -> Eigen::Vector3d {
      return r * Eigen::Vector3d(lx, 0, lz);
    };
    box(x, z, 1.8, 4.3, 0.3, 1.0, yaw, paint);
    const Eigen::Vector3d cabin = at(0.0, -0.2);
    box(x + cabin.x(), z + cabin.z(), 1.6, 2.3, 1.0, 1.5, yaw, p.glass);
    for (double lx : {-0.79, 0.79}) {
      for (double lz : {-1.35, 1.35}) {
        const Eigen::Vector3d w = at(lx, lz);
        box(x + w.x(), z + w.z(), 0.22, 0.65, 0.0, 0.6, yaw, p.tyre);
      }
    }
    scene_.endGroup();
  }

  /// The untextured dark panel van with its rear face at z_rear, seen from behind. Its top stays
  /// below the highest LiDAR beam at that distance, so the LiDAR covers all of it.
  void van(double x, double z_rear, const Palette& p) {
    constexpr double kLength = 5.0;
    scene_.beginGroup();
    box(x, z_rear + 0.5 * kLength, 2.3, kLength, 0.35, 2.05, 0.0, p.van);
    for (double lx : {-0.9, 0.9}) {
      for (double lz : {0.8, kLength - 0.9}) {
        box(x + lx, z_rear + lz, 0.28, 0.7, 0.0, 0.7, 0.0, p.tyre);
      }
    }
    scene_.endGroup();
  }

  void pole(double x, double z, double radius, double height, int material) {
    scene_.addVerticalCylinder(Eigen::Vector3d(x, ground_y_, z), radius, height, material);
  }

 private:
  Scene& scene_;
  double ground_y_;
  Rng rng_;
};

void addBuildings(StreetBuilder& b, const Palette& p) {
  const std::vector<int>& f = p.facades;
  // Left side, facade at x = -9 with an alley at 22 < z < 30 and a block behind it.
  b.building(-30.0, -9.0, -100.0, 22.0, 14.0 + b.jitter(2.0), f[0]);
  b.building(-30.0, -9.0, 30.0, 95.0, 11.0 + b.jitter(2.0), f[1]);
  b.building(-42.0, -22.0, 21.0, 31.0, 18.0 + b.jitter(2.0), f[2]);
  // Right side, facade at x = 8 with an alley at 38 < z < 45.
  b.building(8.0, 30.0, -100.0, 38.0, 12.0 + b.jitter(2.0), f[2]);
  b.building(8.0, 30.0, 45.0, 95.0, 16.0 + b.jitter(2.0), f[3]);
  b.building(20.0, 40.0, 37.0, 46.0, 9.0 + b.jitter(1.0), f[1]);
  // Across the far end of the street, and behind the vehicle (the LiDAR sees all around).
  b.building(-45.0, 45.0, 95.0, 110.0, 20.0 + b.jitter(3.0), f[3]);
  b.building(-45.0, 45.0, -115.0, -100.0, 15.0, f[0]);
}

void addVehicles(StreetBuilder& b, const Palette& p) {
  const std::vector<int>& c = p.paints;
  // Parked on the right (x ~ 2.9): the dark van nearest, one car parked at an angle.
  b.van(2.95 + b.jitter(0.1), 10.5 + b.jitter(0.4), p);
  b.car(2.9 + b.jitter(0.1), 21.0 + b.jitter(0.8), 0.0, c[0], p);
  b.car(2.9 + b.jitter(0.1), 28.5 + b.jitter(0.8), 0.0, c[2], p);
  b.car(2.6 + b.jitter(0.1), 36.0 + b.jitter(0.8), 0.35, c[1], p);
  // Parked on the left (x ~ -4.4), one oncoming car in the left lane, one ahead in ours.
  b.car(-4.4 + b.jitter(0.1), 12.0 + b.jitter(0.8), 0.0, c[3], p);
  b.car(-4.4 + b.jitter(0.1), 31.0 + b.jitter(0.8), 0.0, c[4], p);
  b.car(-3.0 + b.jitter(0.2), 45.0 + b.jitter(2.0), M_PI, c[2], p);
  b.car(0.2 + b.jitter(0.2), 24.0 + b.jitter(1.0), 0.0, c[1], p);
}

void addStreetFurniture(StreetBuilder& b, const Palette& p) {
  for (double z : {6.0, 18.0, 30.0, 42.0, 54.0}) {
    b.pole(4.6, z + b.jitter(0.6), 0.08 + b.jitter(0.02), 6.0, p.pole);
  }
  for (double z : {8.0, 21.0, 34.0, 47.0}) {
    b.pole(-6.0, z + b.jitter(0.6), 0.08 + b.jitter(0.02), 6.0, p.pole);
  }
  // Traffic sign: a thin pole with a plate facing the traffic.
  const double sign_z = 12.5 + b.jitter(0.5);
  b.pole(4.6, sign_z, 0.04, 2.7, p.pole);
  b.box(4.6, sign_z - 0.06, 0.7, 0.03, 2.0, 2.7, 0.0, p.sign);
  // Slanted billboard on the left pavement: turned towards the street and leaning back.
  const double board_z = 18.0 + b.jitter(0.8);
  b.pole(-7.4, board_z, 0.1, 2.5, p.pole);
  b.box(-7.4, board_z, 3.2, 0.06, 2.4, 4.4, (-50.0 + b.jitter(5.0)) * kDegToRad, p.billboard,
        -12.0 * kDegToRad);
}

}  // namespace

Scene makeStreetScene(const StreetLayout& layout) {
  if (!(layout.camera_height > 0.0)) {
    throw std::invalid_argument("sim::makeStreetScene: camera_height must be > 0 [m]");
  }
  Scene scene(hashCombine(layout.seed, 0x7e47));
  const Palette palette = addPalette(scene);
  // Ground: y = camera_height, surface axes (x across, z along the street).
  scene.addPlane(Eigen::Vector3d(0, -1, 0), -layout.camera_height, Eigen::Vector3d::UnitX(),
                 palette.road);
  StreetBuilder builder(scene, layout);
  addBuildings(builder, palette);
  addVehicles(builder, palette);
  addStreetFurniture(builder, palette);
  return scene;
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
