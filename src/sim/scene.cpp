// Analytic ray casting of planes, oriented boxes and vertical cylinders; shading and sky.
#include "lidar_stereo_fusion/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lidar_stereo_fusion/sim/random.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Slab test of a ray against an axis-aligned box; true when [t_near, t_far] meets (t_min, t_max).
bool rayHitsBounds(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& inv_dir, double t_min, double t_max) {
  double lo = t_min, hi = t_max;
  for (int i = 0; i < 3; ++i) {
    double t1 = (box.min()[i] - origin[i]) * inv_dir[i];
    double t2 = (box.max()[i] - origin[i]) * inv_dir[i];
    if (std::isnan(t1) || std::isnan(t2)) {  // origin on a slab plane with a parallel ray
      if (origin[i] < box.min()[i] || origin[i] > box.max()[i]) return false;
      continue;
    }
    if (t1 > t2) std::swap(t1, t2);
    lo = std::max(lo, t1);
    hi = std::min(hi, t2);
    if (lo > hi) return false;
  }
  return true;
}

bool intersectPlane(const PlaneShape& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                    double t_min, double t_max, Hit* hit) {
  const double denom = p.normal.dot(d);
  if (std::abs(denom) < 1e-12) return false;
  const double t = (p.offset - p.normal.dot(o)) / denom;
  if (!(t > t_min && t < t_max)) return false;
  hit->t = t;
  hit->point = o + t * d;
  hit->normal = denom < 0 ? p.normal : Eigen::Vector3d(-p.normal);
  hit->uv = Eigen::Vector2d(p.u_axis.dot(hit->point), p.v_axis.dot(hit->point));
  return true;
}

/// Surface coordinates on a box face whose outward normal is along local axis `axis`.
Eigen::Vector2d boxFaceUv(const Eigen::Vector3d& local, const Eigen::Vector3d& half, int axis) {
  switch (axis) {
    case 0:  // side faces +-x: along z, height above the bottom (up = -y)
      return Eigen::Vector2d(local.z() + half.z(), half.y() - local.y());
    case 2:  // side faces +-z: along x, height above the bottom
      return Eigen::Vector2d(local.x() + half.x(), half.y() - local.y());
    default:  // top and bottom
      return Eigen::Vector2d(local.x() + half.x(), local.z() + half.z());
  }
}

bool intersectBox(const BoxShape& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                  double t_min, double t_max, Hit* hit) {
  const Eigen::Vector3d lo = b.rotation.transpose() * (o - b.centre);
  const Eigen::Vector3d ld = b.rotation.transpose() * d;
  double t_near = -kInf, t_far = kInf;
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(ld[i]) < 1e-15) {
      if (std::abs(lo[i]) > b.half_extents[i]) return false;
      continue;
    }
    double t1 = (-b.half_extents[i] - lo[i]) / ld[i];
    double t2 = (b.half_extents[i] - lo[i]) / ld[i];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_near) {
      t_near = t1;
      axis = i;
    }
    t_far = std::min(t_far, t2);
  }
  // Only entering hits count: rays are never cast from inside a box.
  if (axis < 0 || t_near > t_far || !(t_near > t_min && t_near < t_max)) return false;
  Eigen::Vector3d local_normal = Eigen::Vector3d::Zero();
  local_normal[axis] = ld[axis] > 0 ? -1.0 : 1.0;
  hit->t = t_near;
  hit->point = o + t_near * d;
  hit->normal = b.rotation * local_normal;
  hit->uv = boxFaceUv(lo + t_near * ld, b.half_extents, axis);
  return true;
}

bool intersectCylinder(const CylinderShape& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                       double t_min, double t_max, Hit* hit) {
  const double y_bottom = c.base.y(), y_top = c.base.y() - c.height;  // y points down
  bool found = false;
  // Side: |(o + t d - base)_xz| = r.
  const double ox = o.x() - c.base.x(), oz = o.z() - c.base.z();
  const double a = d.x() * d.x() + d.z() * d.z();
  if (a > 1e-15) {
    const double b = ox * d.x() + oz * d.z();
    const double cc = ox * ox + oz * oz - c.radius * c.radius;
    const double disc = b * b - a * cc;
    if (disc >= 0) {
      const double t = (-b - std::sqrt(disc)) / a;  // entering intersection
      const double y = o.y() + t * d.y();
      if (t > t_min && t < t_max && y <= y_bottom && y >= y_top) {
        hit->t = t;
        hit->point = o + t * d;
        hit->normal = Eigen::Vector3d(hit->point.x() - c.base.x(), 0, hit->point.z() - c.base.z())
                          .normalized();
        const double angle = std::atan2(hit->normal.z(), hit->normal.x());
        hit->uv = Eigen::Vector2d(angle * c.radius, y_bottom - y);
        t_max = t;
        found = true;
      }
    }
  }
  // Top cap (seen from above only; poles are taller than the cameras).
  if (std::abs(d.y()) > 1e-15) {
    const double t = (y_top - o.y()) / d.y();
    if (t > t_min && t < t_max && o.y() < y_top) {
      const Eigen::Vector3d p = o + t * d;
      const double px = p.x() - c.base.x(), pz = p.z() - c.base.z();
      if (px * px + pz * pz <= c.radius * c.radius) {
        hit->t = t;
        hit->point = p;
        hit->normal = Eigen::Vector3d(0, -1, 0);
        hit->uv = Eigen::Vector2d(px, pz);
        found = true;
      }
    }
  }
  return found;
}

Eigen::AlignedBox3d boxBounds(const BoxShape& b) {
  Eigen::AlignedBox3d bounds;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d s((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
    bounds.extend(b.centre + b.rotation * s.cwiseProduct(b.half_extents));
  }
  return bounds;
}

}  // namespace

Scene::Scene(uint64_t texture_seed) : texture_seed_(texture_seed) {}

int Scene::addMaterial(const Material& material) {
  if (!(material.albedo.minCoeff() >= 0.0 && material.albedo.maxCoeff() <= 1.0)) {
    throw std::invalid_argument("sim::Scene: material albedo must be in [0, 1]");
  }
  if (!(material.wavelength_m > 0.0) || material.octaves < 0 || material.contrast < 0.0) {
    throw std::invalid_argument(
        "sim::Scene: material needs wavelength_m > 0, octaves >= 0, contrast >= 0");
  }
  materials_.push_back(material);
  return static_cast<int>(materials_.size()) - 1;
}

const Material& Scene::material(int id) const {
  if (id < 0 || id >= numMaterials()) {
    throw std::out_of_range("sim::Scene: no material " + std::to_string(id));
  }
  return materials_[id];
}

void Scene::beginGroup() {
  if (open_group_ >= 0) throw std::logic_error("sim::Scene: beginGroup() inside a group");
  Group g;
  g.first = g.end = numPrimitives();
  groups_.push_back(g);
  open_group_ = static_cast<int>(groups_.size()) - 1;
}

void Scene::endGroup() {
  if (open_group_ < 0) throw std::logic_error("sim::Scene: endGroup() without beginGroup()");
  open_group_ = -1;
}

int Scene::addPrimitive(const Shape& shape, int material, const Eigen::AlignedBox3d& bounds,
                        bool bounded) {
  this->material(material);  // throws on a bad id
  primitives_.push_back({shape, material});
  const int index = numPrimitives() - 1;
  if (open_group_ >= 0) {
    Group& g = groups_[open_group_];
    g.end = index + 1;
    g.bounded = g.bounded && bounded;
    g.bounds.extend(bounds);
  } else {
    Group g;
    g.first = index;
    g.end = index + 1;
    g.bounded = bounded;
    g.bounds = bounds;
    groups_.push_back(g);
  }
  return index;
}

int Scene::addPlane(const Eigen::Vector3d& normal, double offset, const Eigen::Vector3d& u_axis,
                    int material) {
  if (!(normal.norm() > 0.0)) throw std::invalid_argument("sim::Scene::addPlane: zero normal");
  PlaneShape p;
  p.normal = normal.normalized();
  p.offset = offset / normal.norm();
  p.u_axis = u_axis - u_axis.dot(p.normal) * p.normal;
  if (!(p.u_axis.norm() > 1e-9)) {
    throw std::invalid_argument("sim::Scene::addPlane: u_axis is parallel to the normal");
  }
  p.u_axis.normalize();
  p.v_axis = p.normal.cross(p.u_axis);
  return addPrimitive(p, material, Eigen::AlignedBox3d(), false);
}

int Scene::addBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extents,
                  const Eigen::Matrix3d& rotation, int material) {
  if (!(half_extents.minCoeff() > 0.0)) {
    throw std::invalid_argument("sim::Scene::addBox: half extents must be > 0 [m]");
  }
  if ((rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          1e-9 ||
      rotation.determinant() < 0.0) {
    throw std::invalid_argument("sim::Scene::addBox: rotation is not a rotation matrix");
  }
  const BoxShape b{centre, half_extents, rotation};
  return addPrimitive(b, material, boxBounds(b), true);
}

int Scene::addVerticalCylinder(const Eigen::Vector3d& base, double radius, double height,
                               int material) {
  if (!(radius > 0.0) || !(height > 0.0)) {
    throw std::invalid_argument("sim::Scene::addVerticalCylinder: radius and height must be > 0");
  }
  const CylinderShape c{base, radius, height};
  const Eigen::AlignedBox3d bounds(base - Eigen::Vector3d(radius, height, radius),
                                   base + Eigen::Vector3d(radius, 0.0, radius));
  return addPrimitive(c, material, bounds, true);
}

bool Scene::intersectPrimitive(int index, const Eigen::Vector3d& origin,
                               const Eigen::Vector3d& direction, double t_min, double t_max,
                               Hit* hit) const {
  const Shape& shape = primitives_[index].shape;
  if (const auto* plane = std::get_if<PlaneShape>(&shape)) {
    return intersectPlane(*plane, origin, direction, t_min, t_max, hit);
  }
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    return intersectBox(*box, origin, direction, t_min, t_max, hit);
  }
  return intersectCylinder(std::get<CylinderShape>(shape), origin, direction, t_min, t_max, hit);
}

bool Scene::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_min,
                      double t_max, Hit* hit) const {
  const Eigen::Vector3d inv_dir = direction.cwiseInverse();
  bool found = false;
  Hit candidate;
  for (const Group& g : groups_) {
    if (g.bounded && !rayHitsBounds(g.bounds, origin, inv_dir, t_min, t_max)) continue;
    for (int i = g.first; i < g.end; ++i) {
      if (intersectPrimitive(i, origin, direction, t_min, t_max, &candidate)) {
        t_max = candidate.t;
        candidate.material = primitives_[i].material;
        candidate.primitive = i;
        found = true;
        if (!hit) return true;  // any-hit query
        *hit = candidate;
      }
    }
  }
  return found;
}

bool Scene::segmentBlocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                           double tolerance_m) const {
  const Eigen::Vector3d delta = to - from;
  const double length = delta.norm();
  if (!(length > tolerance_m)) return false;
  return intersect(from, delta / length, 0.0, length - tolerance_m, nullptr);
}

Eigen::Vector3d Scene::skyColour(const Eigen::Vector3d& direction) const {
  const double up = std::clamp(-direction.y(), 0.0, 1.0);
  return lighting.sky_horizon + (lighting.sky_zenith - lighting.sky_horizon) * std::sqrt(up);
}

uint64_t Scene::surfaceSeed(int primitive) const {
  return hashCombine(texture_seed_, static_cast<uint64_t>(primitive));
}

double Scene::pixelFootprint(const Hit& hit, const Eigen::Vector3d& filter_centre,
                             double focal_px) {
  const Eigen::Vector3d to_point = hit.point - filter_centre;
  const double distance = to_point.norm();
  if (!(distance > 0.0)) return 0.0;
  const Eigen::Vector3d ray = to_point / distance;
  const double cos_axis = std::max(ray.z(), 0.1);  // off-axis angle
  const double cos_incidence = std::max(std::abs(hit.normal.dot(ray)), 0.05);
  return distance * cos_axis / focal_px * std::sqrt(cos_axis / cos_incidence);
}

Eigen::Vector3d Scene::radiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                const Eigen::Vector3d& filter_centre, double focal_px) const {
  Hit hit;
  if (!intersect(origin, direction, 0.0, kInf, &hit)) return skyColour(direction);
  const Eigen::Vector3d albedo =
      texturedAlbedo(materials_[hit.material], hit.uv, pixelFootprint(hit, filter_centre, focal_px),
                     surfaceSeed(hit.primitive));
  const Eigen::Vector3d& sun = lighting.sun_direction;
  double direct = std::max(0.0, hit.normal.dot(sun));
  if (direct > 0.0 && lighting.shadows &&
      intersect(hit.point + 1e-6 * std::max(1.0, hit.t) * hit.normal, sun, 0.0, kInf, nullptr)) {
    direct = 0.0;
  }
  return albedo * (lighting.ambient + (1.0 - lighting.ambient) * direct);
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
