// A tiny exact ray caster for the synthetic street scene: planes, oriented boxes and vertical
// cylinders with procedural materials, Lambertian shading with a sun, hard shadows and a sky.
//
// Frame ("street frame"): x right, y down, z forward [m], i.e. the left camera's optical axes at
// frame 0. All intersections are analytic (double precision), so depths are exact.
#pragma once

#include <cstdint>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "lidar_stereo_fusion/sim/texture.h"

namespace lidar_stereo_fusion {
namespace sim {

/// First intersection of a ray with the scene.
struct Hit {
  double t = 0.0;                                   ///< distance along the (unit) ray direction [m]
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< street frame [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, facing the ray's origin
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();      ///< surface coordinates [m]
  int material = -1;
  int primitive = -1;
};

/// Sun and sky. Shading is view-independent (Lambertian), so both cameras see the same colour.
struct Lighting {
  Eigen::Vector3d sun_direction = Eigen::Vector3d(0.35, -0.85, -0.40).normalized();  ///< to the sun
  double ambient = 0.45;  ///< fraction of light that reaches surfaces in shadow
  bool shadows = true;
  Eigen::Vector3d sky_horizon{0.86, 0.89, 0.93};  ///< linear RGB
  Eigen::Vector3d sky_zenith{0.42, 0.60, 0.90};   ///< linear RGB
};

/// Primitive shapes (street frame).
struct PlaneShape {
  Eigen::Vector3d normal;          ///< unit; the plane is {X : normal . X = offset}
  double offset;                   ///< [m]
  Eigen::Vector3d u_axis, v_axis;  ///< unit surface axes (uv = (X . u_axis, X . v_axis))
};
struct BoxShape {
  Eigen::Vector3d centre;        ///< [m]
  Eigen::Vector3d half_extents;  ///< [m] along the box axes
  Eigen::Matrix3d rotation;      ///< street_from_box: columns are the box axes
};
struct CylinderShape {
  Eigen::Vector3d base;  ///< centre of the bottom [m] (the axis points up, i.e. along -y)
  double radius;         ///< [m]
  double height;         ///< [m]
};

class Scene {
 public:
  /// `texture_seed` feeds every surface's noise, so scenes of different seeds look different.
  explicit Scene(uint64_t texture_seed = 0);

  /// Adds a material; returns its id.
  int addMaterial(const Material& material);
  const Material& material(int id) const;
  int numMaterials() const { return static_cast<int>(materials_.size()); }
  int numPrimitives() const { return static_cast<int>(primitives_.size()); }

  /// Primitives added between beginGroup() and endGroup() share one bounding box that rays test
  /// first (e.g. the boxes of a car). Outside a group every primitive is its own group.
  void beginGroup();
  void endGroup();

  /// Infinite plane {X : normal . X = offset} [m]. `u_axis` (made orthogonal to the normal) is the
  /// first surface axis; the second is normal x u_axis. Returns the primitive id.
  int addPlane(const Eigen::Vector3d& normal, double offset, const Eigen::Vector3d& u_axis,
               int material);
  /// Box with half sizes `half_extents` [m] along the columns of `rotation` (street_from_box).
  /// Surface coordinates of a side face: (position along the face, height above the box bottom,
  /// where "up" is -box_y); of the top and bottom faces: (box x, box z).
  int addBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
             const Eigen::Matrix3d& rotation, int material);
  /// Upright cylinder standing on `base` (axis along -y), with a top cap. uv = (arc length,
  /// height above the base) [m].
  int addVerticalCylinder(const Eigen::Vector3d& base, double radius, double height, int material);

  /// Nearest hit with t in (t_min, t_max) along `origin` + t * `direction` (direction unit).
  /// With hit == nullptr, answers only whether there is any hit (faster).
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_min,
                 double t_max, Hit* hit) const;

  /// True when the open segment from `from` to `to` hits a surface closer to `from` than
  /// |to - from| - tolerance_m (so a surface point `to` does not block itself).
  bool segmentBlocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                      double tolerance_m) const;

  /// Linear RGB in [0, 1] seen along the ray: the shaded textured surface, or the sky.
  /// The texture pre-filter is sized by the pixel footprint of a pinhole camera at `filter_centre`
  /// looking along +z with focal length `focal_px` [px]. Pass the same camera (the left one) for
  /// both views: then a surface point has exactly the same colour in both.
  Eigen::Vector3d radiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& filter_centre, double focal_px) const;

  /// Size [m] of one pixel of that camera on the surface at `hit` (the square root of the
  /// footprint's area: z / f * sqrt(cos(off-axis angle) / cos(incidence))).
  static double pixelFootprint(const Hit& hit, const Eigen::Vector3d& filter_centre,
                               double focal_px);

  /// Colour of the sky in `direction` (linear RGB).
  Eigen::Vector3d skyColour(const Eigen::Vector3d& direction) const;

  /// Noise seed of a primitive's surface.
  uint64_t surfaceSeed(int primitive) const;

  Lighting lighting;

 private:
  using Shape = std::variant<PlaneShape, BoxShape, CylinderShape>;
  struct Primitive {
    Shape shape;
    int material;
  };
  struct Group {
    Eigen::AlignedBox3d bounds;  ///< empty() for unbounded groups (planes)
    bool bounded = true;
    int first = 0, end = 0;  ///< primitives [first, end)
  };

  int addPrimitive(const Shape& shape, int material, const Eigen::AlignedBox3d& bounds,
                   bool bounded);
  bool intersectPrimitive(int index, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& direction, double t_min, double t_max,
                          Hit* hit) const;

  uint64_t texture_seed_;
  std::vector<Material> materials_;
  std::vector<Primitive> primitives_;
  std::vector<Group> groups_;
  int open_group_ = -1;  ///< index into groups_ while a group is open
};

}  // namespace sim
}  // namespace lidar_stereo_fusion
