// PatchMatch search steps (METHOD.md section 3): random initialisation, spatial propagation, plane
// refinement and view propagation, all restricted to the pixel's search range (the scan-line
// bounds). Private to the core; exposed for the per-step tests.
//
// Readings taken here:
//  * A plane is accepted for pixel p only if its disparity at p lies in [lo(p), hi(p)] from the
//    scan lines above and below (plus bound_margin), and always in [d_min, d_max] of the image.
//  * At the finest level that searches after a coarse start (full size, or 1/search_scale), the
//    left view polishes each plane with a sub-pixel step (subpixelStep), after a random
//    refinement only if fine_refine; at full size the right view, if searched at all
//    (fine_lr_check), by propagation only (PatchMatchParams::fine_subpixel, fine_refine,
//    fine_right_view, fine_lr_check).
//  * Refinement starts from Delta_d_max = max(|d_up - d_down|, min_refine_range) between scan
//    lines (else half the image's disparity range), Delta_n_max = 1; both halve until
//    Delta_d_max < 0.1 px. At a level that starts from the planes of a coarser one (coarse
//    start), every pixel refines from fine_refine_range instead: the coarse level has searched
//    the bounds already.
//  * Locked pixels (prior confidence >= lock_confidence) keep the prior's plane: they are not
//    searched and receive no view propagation, but offer their plane to their neighbours.
//  * After a coarse start, pixels without scan-line bounds that the level below's left-right
//    check marks inconsistent are left to the hole filling (skip_inconsistent, leaveToFill): not
//    searched, they pass the plane before them in the row on.
//  * Parallelism: the image is cut into horizontal strips of kStripRows rows processed in two
//    phases (every second strip in parallel, then the others), each strip swept in the paper's
//    order. A second-phase strip starts as soon as its two neighbours are done, without waiting
//    for the whole first phase. Adjacent strips are never written at the same time, so the sweep
//    is race-free; random numbers come from a counter-based generator keyed by (seed, view,
//    iteration, pixel), so the result does not depend on the number of threads.
#pragma once

#include "lidar_stereo_fusion/core/patchmatch/cost.h"
#include "lidar_stereo_fusion/core/patchmatch/params.h"
#include "lidar_stereo_fusion/core/patchmatch/plane.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

/// How a level searches one view (the driver decides per level and view, patchmatch.cpp).
struct SearchOptions {
  bool refine = true;     ///< random plane refinement after spatial propagation
  bool subpixel = false;  ///< subpixelStep() ends the pixel's search (after refinement if refine)
  /// [px] candidates whose disparity at the pixel is within this of the current plane's are not
  /// evaluated, and a pixel with no other candidate builds no window (0: only nearlySame ones).
  /// For a view that only serves the left-right check (tolerance lr_max_diff), such a candidate
  /// could move its verdict by no more than this.
  float tolerance = 0.f;
};

class PlaneSearch {
 public:
  PlaneSearch(const PatchMatchParams& params, ViewState& self, const ViewState& other,
              const SearchOptions& options = SearchOptions());

  const MatchingCost& cost() const { return cost_; }

  /// Whether disparity d at (x, y) is inside the search range of the pixel.
  bool admissible(int x, int y, float d) const;

  /// Initial plane: the prior's plane where the prior has an admissible value (with
  /// init_from_prior), else a random disparity in the search range and a random normal (or the
  /// prior's slope with init_normal_from_prior); front-parallel when !slanted.
  Plane initialPlane(int x, int y, Rng& rng) const;

  /// One step of a sweep at (x, y): spatial propagation from the left/upper (forward) or
  /// right/lower neighbour, then plane refinement and/or the sub-pixel step (SearchOptions; with
  /// neither, propagation only). Does nothing on a pixel locked to the prior;
  /// polishes a pixel settled by the coarse level (polishSettled); a pixel left to the fill
  /// (leaveToFill) takes the plane of the pixel before it in the row, unevaluated.
  void processPixel(int x, int y, bool forward, int iteration, WindowCache& cache) const;

  /// Plane refinement and/or the sub-pixel step alone (no spatial propagation) of a pixel settled
  /// by the coarse level, in the left view only: its plane comes from a level of half the size,
  /// whose refinement stops at 0.1 px there (0.2 px here).
  void polishSettled(int x, int y, int idx, int iteration, WindowCache& cache) const;

  /// Whether tryPlane would evaluate `candidate` against `current`: admissible at (x, y), not
  /// nearlySame, not within SearchOptions::tolerance and, where the sub-pixel step ends the
  /// search, not parallel to `current` within half its step kMinRefineStep at (x, y).
  bool worthTrying(int x, int y, const Plane& candidate, const Plane& current) const;

  /// Replaces (best, best_cost) by `candidate` when it is admissible and cheaper.
  void tryPlane(int x, int y, const Plane& candidate, const WindowCache& cache, Plane& best,
                float& best_cost) const;

  /// The cost of the pixel's current plane over `cache` (its window), computed and stored on the
  /// first call after initialisation.
  float currentCost(int idx, const WindowCache& cache) const;

  /// Plane refinement (random perturbations of d and n, halving ranges), then subpixelStep()
  /// when the options ask for it.
  void refine(int x, int y, const WindowCache& cache, Rng& rng, Plane& best,
              float& best_cost) const;

  /// Sub-pixel step on d with the normal kept, by equiangular line fitting (Shimizu & Okutomi
  /// 2001; the costs are sums of absolute differences, V-shaped around their minimum, where a
  /// parabola's vertex is biased toward the middle sample): for the planes shifted by -h, 0, +h
  /// (h = kMinRefineStep, d's last refinement step), the steeper side gives the V's slope and the
  /// two lines of equal and opposite slope meet at
  ///   t = h (C(-h) - C(+h)) / (2 (max(C(-h), C(+h)) - C(0))),
  /// rounded to a multiple of h / 8; where |t| <= h the plane shifted by t replaces the best,
  /// unevaluated (best_cost becomes kUnknownCost), elsewhere (no V with its vertex between -h and
  /// +h) the cheapest of the three.
  void subpixelStep(int x, int y, const WindowCache& cache, Plane& best, float& best_cost) const;

 private:
  void initRange(int x, int y, float& lo, float& hi) const;
  void randomNormal(Rng& rng, float& nx, float& ny, float& nz) const;

  static constexpr float kMinNormalZ = 0.1f;     // rejects planes steeper than ~84 degrees
  static constexpr float kMinRefineStep = 0.1f;  // paper: stop when Delta_d_max < 0.1

  const PatchMatchParams& p_;
  ViewState& self_;
  MatchingCost cost_;
  SearchOptions options_;
};

constexpr int kStripRows = 12;

/// Marks a cost not computed yet (ViewState::cost after initialise).
constexpr float kUnknownCost = -1.f;

/// Initial planes of a view (view 0 = left, 1 = right); their costs are left kUnknownCost.
void initialise(const PlaneSearch& search, ViewState& v, const PatchMatchParams& p, int view);

/// One sweep of spatial propagation + refinement over a view (strips in two phases, a
/// second-phase strip starting once its neighbours are done).
void sweep(const PlaneSearch& search, ViewState& v, const PatchMatchParams& p, int iteration);

/// View propagation: every pixel of `src` offers its plane, transferred into the other view, to
/// the pixel it matches in `dst`. Rows are independent, so rows run in parallel.
void propagateView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
                   const PatchMatchParams& p, bool left_to_right);

/// View propagation before a sweep of `dst`: as propagateView, but each plane is only offered
/// (ViewState::offer) and tried when the sweep visits its pixel, with the window the visit builds
/// anyway. Of several planes offered to one pixel, the one of the nearer surface is kept (the
/// source pixel that comes last in visibility order): it is the surface that view sees.
void offerView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
               const PatchMatchParams& p, bool left_to_right);

/// Threads to use (num_threads, or all cores for 0).
int threadCount(const PatchMatchParams& p);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
