// The synthetic street: a road between building blocks (with alleys), parked and moving cars,
// a dark untextured van (the region where stereo alone fails), thin poles, a traffic sign,
// a slanted billboard and sky. Deterministic from a seed (object placement jitter and textures).
#pragma once

#include <cstdint>

#include "lidar_stereo_fusion/sim/scene.h"

namespace lidar_stereo_fusion {
namespace sim {

/// Layout of the street in the street frame (x right, y down, z forward; the left camera of frame
/// 0 at the origin). The ground is the plane y = camera_height [m]; the road spans
/// -5.5 <= x < 4.0 m, the ego vehicle drives along +z in the right lane (x = 0).
struct StreetLayout {
  double camera_height = 1.65;  ///< height of the left camera above the ground [m] (KITTI 1.65)
  uint64_t seed = 1;            ///< placement jitter and texture noise
};

/// Builds the street scene.
Scene makeStreetScene(const StreetLayout& layout);

}  // namespace sim
}  // namespace lidar_stereo_fusion
