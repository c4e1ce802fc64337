// PatchMatch search steps: initialisation, spatial propagation, plane refinement (propagation.h).
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

PlaneSearch::PlaneSearch(const PatchMatchParams& params, ViewState& self, const ViewState& other,
                         const SearchOptions& options)
    : p_(params), self_(self), cost_(params, self, other), options_(options) {}

bool PlaneSearch::admissible(int x, int y, float d) const {
  if (!(d >= self_.d_min && d <= self_.d_max)) return false;
  if (p_.use_lidar_bounds && self_.bounded(x, y)) return d >= self_.lo(y, x) && d <= self_.hi(y, x);
  return true;
}

void PlaneSearch::initRange(int x, int y, float& lo, float& hi) const {
  lo = self_.d_min;
  hi = self_.d_max;
  if (p_.use_lidar_bounds && self_.bounded(x, y)) {
    lo = std::max(lo, self_.lo(y, x));
    hi = std::min(hi, self_.hi(y, x));
    if (hi < lo) hi = lo;
  }
}

Plane PlaneSearch::initialPlane(int x, int y, Rng& rng) const {
  const int idx = y * self_.width + x;
  if (self_.locked[idx] == kLockedToPrior) return priorPlane(self_, x, y);
  if (self_.locked[idx] == kSettledByGuide || self_.locked[idx] == kKeptFromGuide ||
      (self_.locked[idx] == kLeftToFill && !self_.guide.empty())) {
    return self_.guide[idx];
  }
  if (!self_.guide.empty()) {
    const Plane& g = self_.guide[idx];
    if (admissible(x, y, g.at(static_cast<float>(x), static_cast<float>(y)))) return g;
  }
  float lo, hi;
  initRange(x, y, lo, hi);
  float d = rng.uniform(lo, hi);
  const float prior = self_.prior.empty() ? 0.f : self_.prior(y, x);
  if (p_.init_from_prior && prior > 0.f && admissible(x, y, prior)) d = prior;
  if (!p_.slanted) return Plane{0.f, 0.f, d};
  float a, b;
  if (p_.init_from_prior && p_.init_normal_from_prior && prior > 0.f &&
      priorSlope(self_, x, y, a, b)) {
    return Plane{a, b, d - a * x - b * y};
  }
  float nx, ny, nz;
  randomNormal(rng, nx, ny, nz);
  return planeFromNormal(static_cast<float>(x), static_cast<float>(y), d, nx, ny, nz);
}

void PlaneSearch::randomNormal(Rng& rng, float& nx, float& ny, float& nz) const {
  // Uniform direction on the hemisphere facing the camera, rejecting near-grazing planes.
  do {
    nx = rng.uniform(-1.f, 1.f);
    ny = rng.uniform(-1.f, 1.f);
    nz = rng.uniform(-1.f, 1.f);
    const float norm = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (norm < 1e-3f || norm > 1.f) {
      nz = 0.f;
      continue;
    }
    nx /= norm;
    ny /= norm;
    nz = std::abs(nz) / norm;
  } while (nz < kMinNormalZ);
}

void PlaneSearch::processPixel(int x, int y, bool forward, int iteration,
                               WindowCache& cache) const {
  const int idx = y * self_.width + x;
  if (self_.locked[idx] == kLockedToPrior || self_.locked[idx] == kKeptFromGuide) return;
  if (self_.locked[idx] == kSettledByGuide) {
    if (self_.match_sign < 0) polishSettled(x, y, idx, iteration, cache);
    return;
  }
  // Spatial propagation: forward sweeps look left/up, backward sweeps right/down.
  const int step = forward ? -1 : 1;
  const int nx = x + step, ny = y + step;
  if (self_.locked[idx] == kLeftToFill) {
    // Not searched (leaveToFill): it passes the plane before it in the row on, so that the next
    // searched pixel is offered the last searched plane, as the hole filling would spread it.
    if (nx >= 0 && nx < self_.width) {
      self_.planes[idx] = self_.planes[idx + step];
      self_.cost[idx] = kUnknownCost;
    }
    return;
  }
  const bool has_x = nx >= 0 && nx < self_.width, has_y = ny >= 0 && ny < self_.height;
  if (!options_.refine && !options_.subpixel) {
    // Propagation alone: no window unless some candidate is worth a cost. (The pixel's own cost,
    // unknown after initialisation, is then computed when first asked for, from the same
    // window: the same float.)
    const Plane& own = self_.planes[idx];
    if (!(self_.offered[idx] && worthTrying(x, y, self_.offer[idx], own)) &&
        !(has_x && worthTrying(x, y, self_.planes[idx + step], own)) &&
        !(has_y && worthTrying(x, y, self_.planes[idx + step * self_.width], own))) {
      self_.offered[idx] = 0;
      return;
    }
  }
  cost_.buildWindow(x, y, cache);
  Plane best = self_.planes[idx];
  float best_cost = currentCost(idx, cache);
  if (self_.offered[idx]) {  // view propagation (offerView)
    tryPlane(x, y, self_.offer[idx], cache, best, best_cost);
    self_.offered[idx] = 0;
  }
  if (has_x) tryPlane(x, y, self_.planes[idx + step], cache, best, best_cost);
  if (has_y) tryPlane(x, y, self_.planes[idx + step * self_.width], cache, best, best_cost);
  if (options_.refine) {
    Rng rng(streamKey(p_.seed, self_.match_sign < 0 ? 0 : 1, iteration, idx));
    refine(x, y, cache, rng, best, best_cost);
  } else if (options_.subpixel) {
    subpixelStep(x, y, cache, best, best_cost);
  }
  self_.planes[idx] = best;
  self_.cost[idx] = best_cost;
}

void PlaneSearch::polishSettled(int x, int y, int idx, int iteration, WindowCache& cache) const {
  cost_.buildWindow(x, y, cache);
  Plane best = self_.planes[idx];
  float best_cost = currentCost(idx, cache);
  if (options_.refine) {
    Rng rng(streamKey(p_.seed, 0, iteration, idx));
    refine(x, y, cache, rng, best, best_cost);  // from +-fine_refine_range: the pixel has a guide
  } else if (options_.subpixel) {
    subpixelStep(x, y, cache, best, best_cost);
  }
  self_.planes[idx] = best;
  self_.cost[idx] = best_cost;
}

float PlaneSearch::currentCost(int idx, const WindowCache& cache) const {
  if (self_.cost[idx] == kUnknownCost) {
    self_.cost[idx] = cost_.aggregate(cache, self_.planes[idx], std::numeric_limits<float>::max());
  }
  return self_.cost[idx];
}

bool PlaneSearch::worthTrying(int x, int y, const Plane& candidate, const Plane& current) const {
  const float fx = static_cast<float>(x), fy = static_cast<float>(y);
  const float d = candidate.at(fx, fy);
  const float shift = std::abs(d - current.at(fx, fy));
  if (options_.tolerance > 0.f && shift <= options_.tolerance) return false;
  // The sub-pixel step ending the search probes the current plane moved by -+ kMinRefineStep and
  // fits the cost's vertex between: a parallel candidate moved by no more than half that lies
  // well inside the interval it searches. (Up to the whole step, far surfaces lost precision:
  // the fit is least reliable near the interval's ends.)
  if (options_.subpixel && shift <= 0.5f * kMinRefineStep && parallel(candidate, current)) {
    return false;
  }
  return !nearlySame(candidate, current, fx, fy) && admissible(x, y, d);
}

void PlaneSearch::tryPlane(int x, int y, const Plane& candidate, const WindowCache& cache,
                           Plane& best, float& best_cost) const {
  // Propagation often offers (nearly) the plane the pixel already has: evaluating it cannot
  // change the result by more than the tolerance (kSamePlaneTolerance or the options'), so skip
  // it.
  if (!worthTrying(x, y, candidate, best)) return;
  const float c = cost_.aggregate(cache, candidate, best_cost);
  if (c < best_cost) {
    best = candidate;
    best_cost = c;
  }
}

void PlaneSearch::refine(int x, int y, const WindowCache& cache, Rng& rng, Plane& best,
                         float& best_cost) const {
  float dd;
  if (!self_.guide.empty()) {
    dd = static_cast<float>(p_.fine_refine_range);  // the coarse start found the neighbourhood
  } else if (p_.use_lidar_bounds && self_.bounded(x, y)) {
    dd = std::max(self_.range(y, x), static_cast<float>(p_.min_refine_range));
  } else {
    dd = 0.5f * (self_.d_max - self_.d_min);
  }
  float dn = 1.f;
  const float fx = static_cast<float>(x), fy = static_cast<float>(y);
  // The best plane's normal, computed again only when a candidate replaces it.
  float best_nx = 0.f, best_ny = 0.f, best_nz = 0.f;
  bool normal_known = false;
  while (dd >= kMinRefineStep) {
    const float d = best.at(fx, fy) + rng.uniform(-dd, dd);
    Plane candidate{0.f, 0.f, d};
    if (p_.slanted) {
      if (!normal_known) normalOf(best, best_nx, best_ny, best_nz);
      normal_known = true;
      const float nx = best_nx + rng.uniform(-dn, dn);
      const float ny = best_ny + rng.uniform(-dn, dn);
      const float nz = best_nz + rng.uniform(-dn, dn);
      const float norm = std::sqrt(nx * nx + ny * ny + nz * nz);
      if (norm > 1e-6f && std::abs(nz / norm) >= kMinNormalZ) {
        candidate = nz < 0.f ? planeFromNormal(fx, fy, d, -nx / norm, -ny / norm, -nz / norm)
                             : planeFromNormal(fx, fy, d, nx / norm, ny / norm, nz / norm);
      } else {
        candidate = Plane{best.a, best.b, d - best.a * fx - best.b * fy};
      }
    }
    const float before = best_cost;
    tryPlane(x, y, candidate, cache, best, best_cost);
    if (best_cost != before) normal_known = false;
    dd *= 0.5f;
    dn *= 0.5f;
  }
  if (options_.subpixel) subpixelStep(x, y, cache, best, best_cost);
}

void PlaneSearch::subpixelStep(int x, int y, const WindowCache& cache, Plane& best,
                               float& best_cost) const {
  const float h = kMinRefineStep;
  const float fx = static_cast<float>(x), fy = static_cast<float>(y);
  const Plane lower{best.a, best.b, best.c - h}, upper{best.a, best.b, best.c + h};
  if (!admissible(x, y, lower.at(fx, fy)) || !admissible(x, y, upper.at(fx, fy))) return;
  // The costs at d -+ h in one pass, with each sample's match interpolated on the interval of
  // d's (MatchingCost::aggregateSides): the fit needs the full costs, and two evaluations would
  // cost half as much again.
  float c_lower, c_upper;
  cost_.aggregateSides(cache, best, h, c_lower, c_upper);
  // The steeper side's slope is the V's: rise over h.
  const float rise = std::max(c_lower, c_upper) - best_cost;
  const float vertex = rise > 0.f ? 0.5f * h * (c_lower - c_upper) / rise : 0.f;
  if (!(rise > 0.f) || !(std::abs(vertex) <= h)) {
    // No V with its vertex between the two: keep the cheapest of the three, whose cost is
    // computed if ever asked for (the sides are C only where the other view is linear).
    if (c_lower < best_cost && c_lower <= c_upper) {
      best = lower;
      best_cost = kUnknownCost;
    } else if (c_upper < best_cost) {
      best = upper;
      best_cost = kUnknownCost;
    }
    return;
  }
  // The vertex on a grid of h / 8: a continuous shift would move every plane with the slightest
  // change of the input (e.g. a calibration rounded to a unit quaternion), and each moved plane
  // can tip a later comparison; on the grid almost all stay where they were.
  const float quantum = h / 8.f;
  // The vertex is taken without evaluating it (the fit says it is the cheapest; d + t lies
  // between the two admissible shifts): its cost is computed if ever asked for (currentCost).
  const float t = quantum * std::round(vertex / quantum);
  if (t != 0.f) {
    best.c += t;
    best_cost = kUnknownCost;
  }
}

int threadCount(const PatchMatchParams& p) {
  // 0: OpenMP's default team, i.e. every core unless OMP_NUM_THREADS says otherwise (lsf_batch
  // runs one bag_runner per worker with OMP_NUM_THREADS = --threads-per-worker).
  return p.num_threads > 0 ? p.num_threads : omp_get_max_threads();
}

void initialise(const PlaneSearch& search, ViewState& v, const PatchMatchParams& p, int view) {
  // The cost of an initial plane is computed when the pixel is first visited (currentCost), with
  // the window the visit builds anyway; locked pixels are never compared.
  parallelRows(v.height, threadCount(p), [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < v.width; ++x) {
        const int idx = y * v.width + x;
        Rng rng(streamKey(p.seed, view, -1, idx));
        v.planes[idx] = search.initialPlane(x, y, rng);
        v.cost[idx] = kUnknownCost;
      }
    }
  });
}

void sweep(const PlaneSearch& search, ViewState& v, const PatchMatchParams& p, int iteration) {
  const bool forward = iteration % 2 == 0;  // iterations 1, 3, ... (0-based even) go forward
  const int threads = threadCount(p);
  // The strip layout must not depend on the thread count, or results would.
  const int strips = (v.height + kStripRows - 1) / kStripRows;
  // Two phases: forward, the even strips, then the odd ones; backward, counted from the bottom
  // strip, the odd ones first. Within a phase strips are independent, and they are handed out
  // top first in either direction: above the LiDAR, where no pixel is locked, strips take
  // longest.
  const int first_parity = forward ? 0 : strips % 2;
  std::vector<int> order;
  order.reserve(strips);
  for (int phase = 0; phase < 2; ++phase) {
    for (int strip = 0; strip < strips; ++strip) {
      if ((strip % 2 == first_parity) == (phase == 0)) order.push_back(strip);
    }
  }
  // No barrier between the phases: a second-phase strip starts once its two neighbours are done
  // (it reads their rows next to it, and they read its rows as the phase before left them). The
  // data each strip sees is the two-phase order's, so results are the same for any thread count
  // and schedule; a thread taking a second-phase strip waits only for strips already taken,
  // which never wait themselves.
  std::unique_ptr<std::atomic<bool>[]> done(new std::atomic<bool>[strips]);
  for (int i = 0; i < strips; ++i) done[i].store(false, std::memory_order_relaxed);
  const auto ready = [&](int strip) {
    return strip < 0 || strip >= strips || done[strip].load(std::memory_order_acquire);
  };
  parallelFor(strips, threads, [&](int i) {
    const int strip = order[i];
    if (strip % 2 != first_parity) {
      while (!ready(strip - 1) || !ready(strip + 1)) std::this_thread::yield();
    }
    WindowCache cache;
    const int y0 = strip * kStripRows;
    const int y1 = std::min(v.height, y0 + kStripRows);
    if (forward) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < v.width; ++x) search.processPixel(x, y, true, iteration, cache);
    } else {
      for (int y = y1 - 1; y >= y0; --y)
        for (int x = v.width - 1; x >= 0; --x) search.processPixel(x, y, false, iteration, cache);
    }
    done[strip].store(true, std::memory_order_release);
  });
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
