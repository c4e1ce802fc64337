// LiDAR-guided PatchMatch stereo (Bleyer et al. 2011 + the LiDAR term of Xu et al.): the driver.
// The steps live in their own files: plane.h (the plane xi), cost.h/.cpp (C, w, phi),
// propagation.h/.cpp (initialisation, spatial propagation, refinement), view_propagation.cpp,
// post_processing.h/.cpp (left-right check, filling).
//
// Per iteration: left view sweep. In the last `right_iterations` iterations also: view
// propagation of the left planes into the right view, right view sweep, view propagation back
// into the left (unless the right view was swept by propagation alone). Then the left-right check
// and filling. At the full-size level after a coarse start, the left view polishes each pixel's
// plane with a sub-pixel step (fine_subpixel), after a random refinement only if fine_refine; the
// right view is searched only if asked (fine_right_view, or fine_lr_check: by propagation alone),
// else the left-right check is the 1/2-size level's, up-sampled. After a coarse start, the pixels
// without LiDAR bounds that the level below's left-right check marks inconsistent are not searched
// (skip_inconsistent; at 1/2 size the interior of those regions only): they pass the plane before
// them on, as the hole filling would (leaveToFill). With search_scale > 1 a level does not search:
// the level below checks and fills, and this level up-samples its result (upsampledResult); with
// unbounded_scale > 1 the pixels without bounds keep the level below's plane (kKeptFromGuide).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/both_views.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PatchMatchParams: " + message);
}

/// 1 where the pixel's plane is the prior's (the left-right check keeps those), else 0.
std::vector<uint8_t> lockedToPrior(const patchmatch::ViewState& v) {
  std::vector<uint8_t> keep(v.locked.size());
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = v.locked[i] == patchmatch::kLockedToPrior;
  return keep;
}

/// Whether `s` is the reduction factor of a level of the coarse start: 1 or coarse_scale^k,
/// k = 1 .. coarse_levels.
bool isLevelScale(const PatchMatchParams& p, int s) {
  if (s == 1) return true;
  if (p.coarse_scale < 2) return false;
  for (int k = 1, f = p.coarse_scale; k <= p.coarse_levels; ++k, f *= p.coarse_scale) {
    if (s == f) return true;
  }
  return false;
}

cv::Mat3f planeMap(const patchmatch::ViewState& v, int threads) {
  cv::Mat3f map(v.height, v.width);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      const patchmatch::Plane& pl = v.planes[y * v.width + x];
      map(y, x) = cv::Vec3f(pl.a, pl.b, pl.c);
    }
  }
  return map;
}

}  // namespace

void PatchMatchParams::validate() const {
  require(window_radius >= 1 && window_radius <= 50, "window_radius must be in [1, 50]");
  require(window_stride >= 1 && window_stride <= window_radius,
          "window_stride must be in [1, window_radius]");
  require(weight_delta > 0, "weight_delta must be > 0");
  require(std::isfinite(image_smoothing) && image_smoothing >= 0 && image_smoothing <= 5,
          "image_smoothing must be in [0, 5] px");
  require(alpha >= 0 && beta >= 0 && gamma >= 0, "alpha, beta, gamma must be >= 0");
  require(std::abs(alpha + beta + gamma - 1.0) < 1e-6, "alpha + beta + gamma must be 1");
  require(!confidence_weighting || alpha + beta > 0,
          "confidence_weighting needs an image term (alpha + beta > 0)");
  require(lambda_col > 0 && lambda_grad > 0 && lambda_disp > 0, "truncations must be > 0");
  require(iterations >= 0 && iterations <= 100, "iterations must be in [0, 100]");
  require(right_iterations == -1 || right_iterations >= 1,
          "right_iterations must be -1 (every iteration) or >= 1");
  require(bound_margin >= 0, "bound_margin must be >= 0");
  require(min_refine_range >= 0, "min_refine_range must be >= 0");
  require(min_disparity > 0, "min_disparity must be > 0");
  require(max_disparity > min_disparity, "max_disparity must be > min_disparity");
  require(lr_max_diff > 0, "lr_max_diff must be > 0");
  require(median_radius >= 1 && median_radius <= 50, "median_radius must be in [1, 50]");
  require(std::isfinite(lock_confidence) && lock_confidence >= 0,
          "lock_confidence must be >= 0 (> 1 = never lock)");
  require(fill_confidence >= 0 && fill_confidence <= 1, "fill_confidence must be in [0, 1]");
  require(coarse_scale >= 1 && coarse_scale <= 16, "coarse_scale must be in [1, 16] (1 = off)");
  require(coarse_levels >= 1 && coarse_levels <= 4, "coarse_levels must be in [1, 4]");
  require(isLevelScale(*this, search_scale),
          "search_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(isLevelScale(*this, unbounded_scale),
          "unbounded_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(fine_iterations >= 1 && fine_iterations <= 100, "fine_iterations must be in [1, 100]");
  require(std::isfinite(fine_refine_range) && fine_refine_range > 0,
          "fine_refine_range must be > 0");
  require(num_threads >= 0 && num_threads <= 256,
          "num_threads must be in [0, 256] (0 = all cores)");
}

/// Per-object buffers reused across frames (a fresh full-size buffer costs page faults every
/// frame).
struct PatchMatchStereo::Scratch {
  patchmatch::ViewState left, right;
};

PatchMatchStereo::PatchMatchStereo(const PatchMatchParams& params) { setParams(params); }

void PatchMatchStereo::setParams(const PatchMatchParams& params) {
  params.validate();
  params_ = params;
}

PatchMatchResult PatchMatchStereo::levelBelow(const ViewInput& left, const ViewInput& right) {
  const PatchMatchParams& p = params_;
  if (!coarse_) {
    coarse_ = std::make_shared<PatchMatchStereo>(patchmatch::coarseParams(p));
    coarse_->intermediate_ = true;
  }
  coarse_->setParams(patchmatch::coarseParams(p));
  ViewInput coarse_left, coarse_right;
  bothViews(patchmatch::threadCount(p),
            [&] { coarse_left = patchmatch::downsampleView(left, p.coarse_scale); },
            [&] { coarse_right = patchmatch::downsampleView(right, p.coarse_scale); });
  return coarse_->compute(coarse_left, coarse_right);
}

PatchMatchResult PatchMatchStereo::upsampledResult(const ViewInput& left, const ViewInput& right) {
  using namespace patchmatch;
  const PatchMatchParams& p = params_;
  const int threads = threadCount(p);
  const cv::Size size = left.image.size();
  ViewState& lv = scratch_->left;
  preparePrior(left, p, lv);  // the images are the level below's alone
  const PatchMatchResult below = levelBelow(left, right);
  const int s = p.coarse_scale;
  lv.planes = upsamplePlanes(below.planes, s, size, threads);
  PatchMatchResult result;
  result.planes.create(size);
  result.disparity.create(size);
  result.inconsistent = p.lr_check ? upsampleMask(below.inconsistent, s, size)
                                   : cv::Mat1b(size, uchar(0));
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const int idx = y * size.width + x;
      Plane& plane = lv.planes[idx];
      if (lv.locked[idx] == kLockedToPrior) {
        plane = priorPlane(lv, x, y);
        result.inconsistent(y, x) = 0;  // the LiDAR measured it: the check keeps it
      }
      result.planes(y, x) = cv::Vec3f(plane.a, plane.b, plane.c);
      result.disparity(y, x) = plane.at(static_cast<float>(x), static_cast<float>(y));
    }
  }
  if (p.lr_check) {
    fillFromBelow(lv, result.inconsistent.clone(), below.disparity, s,
                  static_cast<float>(p.fill_confidence), result.disparity, threads);
  }
  for (float& d : result.disparity) {
    if (!(d > 0.f) || !std::isfinite(d)) d = 0.f;
  }
  return result;
}

PatchMatchResult PatchMatchStereo::compute(const ViewInput& left, const ViewInput& right) {
  using namespace patchmatch;
  const cv::Size size = left.image.size();
  checkViewInput(left, size, "left");
  checkViewInput(right, size, "right");
  const PatchMatchParams& p = params_;
  if (!scratch_) scratch_ = std::make_shared<Scratch>();
  const bool guided = p.coarse_scale > 1 && std::min(size.width, size.height) >= 4 * p.coarse_scale;
  if (guided && p.search_scale > 1) return upsampledResult(left, right);
  ViewState& lv = scratch_->left;
  ViewState& rv = scratch_->right;
  const int threads = threadCount(p);
  bothViews(threads, [&] { prepareView(left, p, -1.f, lv); },
            [&] { prepareView(right, p, +1.f, rv); });
  const bool two_views = p.view_propagation || p.lr_check;

  int iterations = p.iterations;
  const bool unmatched_bad = p.confidence_weighting && !lv.prior.empty();
  // Whether the full-size right view is searched: without a coarse start always; after one for
  // Bleyer's right view (fine_right_view) or a full-size left-right check (fine_lr_check).
  bool right_view = two_views && (!guided || p.fine_right_view || (p.lr_check && p.fine_lr_check));
  cv::Mat1b inconsistent;  // the left-right check's mask, where it is the level below's
  if (guided) {
    // Coarse start: its planes, up-sampled, are where the full-size search begins.
    const PatchMatchResult coarse = levelBelow(left, right);
    setGuide(upsamplePlanes(coarse.planes, p.coarse_scale, size, threads), p, lv);
    // The coarse level has no left-right check, so without view propagation it has no right view.
    if (right_view && !coarse.right_planes.empty()) {
      setGuide(upsamplePlanes(coarse.right_planes, p.coarse_scale, size, threads), p, rv);
    }
    iterations = p.fine_iterations;
    // The level below's left-right check (its views, at lr_max_diff / coarse_scale).
    cv::Mat1b below;
    if (!coarse.right_disparity.empty() && (p.skip_inconsistent || (p.lr_check && !right_view))) {
      const float max_diff = static_cast<float>(p.lr_max_diff / p.coarse_scale);
      below = leftRightCheck(coarse.disparity, coarse.right_disparity, max_diff, {},
                             unmatched_bad, threads);
    }
    if (p.lr_check && !right_view) {
      if (below.empty()) {
        right_view = true;  // no view propagation below: only a full-size right view can check
      } else {
        inconsistent = upsampleMask(below, p.coarse_scale, size);
      }
    }
    if (p.skip_inconsistent && !below.empty()) {
      if (!inconsistent.empty()) {
        // The fill replaces these pixels' disparity whatever the search finds (a third of the
        // full-size search on KITTI frame 0).
        leaveToFill(inconsistent, lv);
      } else {
        // This level's own check decides. Occluded or ambiguous below, they are mostly so here
        // too, and spreading their neighbours' planes serves them as well as searching them; but
        // the border of each region below, one of its pixels wide, is searched: coarse pixels
        // straddle depth edges, and skipping them would erode foreground objects by up to one
        // coarse pixel (tested).
        cv::Mat1b interior;
        cv::erode(below, interior, cv::Mat());
        leaveToFill(upsampleMask(interior, p.coarse_scale, size), lv);
      }
    }
  }

  // The full-size level after a coarse start polishes the planes it was given: the left view
  // with a sub-pixel step (after random refinement if fine_refine); the right view, if searched,
  // by propagation alone unless fine_right_view.
  SearchOptions left_options, right_options;
  left_options.subpixel = guided && p.fine_subpixel;
  left_options.refine = !guided || p.fine_refine;
  right_options.refine = !guided || p.fine_right_view;
  // An intermediate level (1/2 size of three) refines its right view only with
  // intermediate_refine; else both views only propagate there.
  if (guided && intermediate_ && !p.intermediate_refine) right_options.refine = false;
  // Swept by propagation alone, the right view serves the left-right check only.
  if (!right_options.refine) right_options.tolerance = 0.25f * static_cast<float>(p.lr_max_diff);
  PlaneSearch left_search(p, lv, rv, left_options);
  PlaneSearch right_search(p, rv, lv, right_options);
  initialise(left_search, lv, p, 0);
  if (right_view) initialise(right_search, rv, p, 1);
  // The right view sweeps in the last `right_iterations` iterations only. It serves view
  // propagation and the left-right check; view propagation runs around its sweeps (left -> right
  // before, right -> left after), since in the other iterations the right view would only hand
  // the left view's own planes back.
  const int right_iterations =
      p.right_iterations < 0 ? iterations : std::min(p.right_iterations, iterations);
  for (int it = 0; it < iterations; ++it) {
    sweep(left_search, lv, p, it);
    if (!right_view || it < iterations - right_iterations) continue;
    if (p.view_propagation) {
      // After a coarse start, the right view tries the left planes in its sweep, with the
      // windows the sweep builds anyway; Bleyer's view propagation (the coarsest level, the
      // paper preset, plain PMS) builds one more per pixel, before the sweep.
      if (guided) {
        offerView(lv, right_search, rv, p, true);
      } else {
        propagateView(lv, right_search, rv, p, true);
      }
    }
    sweep(right_search, rv, p, it);
    // A right view swept by propagation alone holds the left planes it was offered or the
    // level below's, which that level's view propagation has handed to the left already: nothing
    // new to hand back (KITTI and Middlebury unchanged without it, a fifth of the level's work).
    if (p.view_propagation && right_options.refine) propagateView(rv, left_search, lv, p, false);
  }

  PatchMatchResult result;
  result.disparity = disparityOf(lv, threads);
  result.planes = planeMap(lv, threads);
  if (right_view) {
    result.right_disparity = disparityOf(rv, threads);
    result.right_planes = planeMap(rv, threads);
  }
  if (p.lr_check) {
    const std::vector<uint8_t> keep = lockedToPrior(lv);
    if (inconsistent.empty()) {
      const float max_diff = static_cast<float>(p.lr_max_diff);
      inconsistent = leftRightCheck(result.disparity, result.right_disparity, max_diff, keep,
                                    unmatched_bad, threads);
    } else {
      for (size_t i = 0; i < keep.size(); ++i) {
        if (keep[i]) inconsistent.data[i] = 0;  // the LiDAR measured it (leftRightCheck's keep)
      }
    }
    result.inconsistent = inconsistent;
    fillHoles(lv, inconsistent.clone(), p.median_radius, static_cast<float>(p.weight_delta),
              static_cast<float>(p.fill_confidence), static_cast<float>(p.max_disparity),
              result.disparity, threads);
  } else {
    result.inconsistent = cv::Mat1b(size, uchar(0));
  }
  // Non-positive or non-finite disparities (holes nothing could fill) are marked empty (0).
  for (float& d : cv::Mat_<float>(result.disparity)) {
    if (!(d > 0.f) || !std::isfinite(d)) d = 0.f;
  }
  return result;
}

}  // namespace lidar_stereo_fusion
