// Box-Muller normals for the deterministic generators of random.h.
#include "lidar_stereo_fusion/sim/random.h"

#include <cmath>

namespace lidar_stereo_fusion {
namespace sim {

double normalFromHashes(uint64_t h1, uint64_t h2) {
  const double u1 = 1.0 - unitFromHash(h1);  // (0, 1]: log is finite
  const double u2 = unitFromHash(h2);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double Rng::normal() {
  const uint64_t h1 = next();
  return normalFromHashes(h1, next());
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
