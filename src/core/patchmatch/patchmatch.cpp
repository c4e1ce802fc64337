// LiDAR-guided PatchMatch stereo (Bleyer et al. 2011 + the LiDAR term of Xu et al.): the driver.
// The steps live in their own files: plane.h (the plane xi), cost.h/.cpp (C, w, phi),
// propagation.h/.cpp (initialisation, spatial propagation, refinement), view_propagation.cpp,
// post_processing.h/.cpp (left-right check, filling); the parameters' checks in params.cpp.
//
// compute() runs the stages in order, one function each:
//   prepareLevel         the views (images, prior, bounds) and what this level does (Level)
//   startFromLevelBelow  coarse start: the planes of the level below, up-sampled, and its
//                        left-right check (checkLevelBelow, skipInconsistent)
//   searchViews          initialisation, then per iteration the left view's sweep and the right
//                        view's (searchRightView: view propagation in, sweep, view propagation
//                        back)
//   postProcess          disparities, left-right check (consistencyCheck), hole filling
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
#include <chrono>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/both_views.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "lidar_stereo_fusion/core/patchmatch/parallel.h"
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {

namespace {

/// 1 where the pixel's plane is the prior's (the left-right check keeps those), else 0.
std::vector<uint8_t> lockedToPrior(const patchmatch::ViewState& v) {
  std::vector<uint8_t> keep(v.locked.size());
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = v.locked[i] == patchmatch::kLockedToPrior;
  return keep;
}

cv::Mat3f planeMap(const patchmatch::ViewState& v, int threads) {
  cv::Mat3f map(v.height, v.width);
  patchmatch::parallelRows(v.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < v.width; ++x) {
        const patchmatch::Plane& pl = v.planes[y * v.width + x];
        map(y, x) = cv::Vec3f(pl.a, pl.b, pl.c);
      }
    }
  });
  return map;
}

/// Marks empty (0) the non-positive or non-finite disparities: holes nothing could fill.
void markEmpty(cv::Mat1f& disparity) {
  for (float& d : disparity) {
    if (!(d > 0.f) || !std::isfinite(d)) d = 0.f;
  }
}

/// Whether a level of `size` starts from a coarse start (a level below at 1 / coarse_scale).
bool hasCoarseStart(const PatchMatchParams& p, const cv::Size& size) {
  return p.coarse_scale > 1 && std::min(size.width, size.height) >= 4 * p.coarse_scale;
}

/// The hole filling's options from the parameters.
patchmatch::FillOptions fillOptions(const PatchMatchParams& p) {
  return {p.median_radius, static_cast<float>(p.weight_delta),
          static_cast<float>(p.fill_confidence), static_cast<float>(p.max_disparity), p.simd_path};
}

}  // namespace

/// What one level of the search does, decided before it starts (compute()).
struct PatchMatchStereo::Level {
  cv::Size size;
  bool guided = false;         ///< starts from the coarse start's planes (levelBelow)
  bool right_view = false;     ///< the right view is searched at this level
  bool unmatched_bad = false;  ///< the left-right check marks the pixels without a match
  int iterations = 0;
  int threads = 1;
  cv::Mat1b inconsistent;  ///< the left-right check's mask, where it is the level below's
};

/// Per-object buffers reused across frames (a fresh full-size buffer costs page faults every
/// frame).
struct PatchMatchStereo::Scratch {
  patchmatch::ViewState left, right;
  ViewInput below_left, below_right;  ///< the views reduced for the level below
};

/// The step timer of one compute(): each lap() names the step that ends there.
struct PatchMatchStereo::Steps {
  using Clock = std::chrono::steady_clock;
  std::vector<PatchMatchStep> list;
  std::string prefix;
  Clock::time_point last;

  void start(int level_scale) {
    list.clear();
    prefix = "1/" + std::to_string(level_scale) + " ";
    last = Clock::now();
  }
  void lap(const std::string& what) {
    const Clock::time_point now = Clock::now();
    list.push_back({prefix + what, std::chrono::duration<double, std::milli>(now - last).count()});
    last = now;
  }
  /// The level below's steps, timed by its own timer.
  void append(const std::vector<PatchMatchStep>& below) {
    list.insert(list.end(), below.begin(), below.end());
    last = Clock::now();
  }
};

PatchMatchStereo::PatchMatchStereo(const PatchMatchParams& params) { setParams(params); }

void PatchMatchStereo::setPlanesOutput(bool planes) { planes_wanted_ = planes; }

void PatchMatchStereo::setParams(const PatchMatchParams& params) {
  params.validate();
  configured_ = params;
  params_ = params;
}

PatchMatchResult PatchMatchStereo::levelBelow(const ViewInput& left, const ViewInput& right,
                                              bool right_planes) {
  const PatchMatchParams& p = params_;
  if (!coarse_) {
    coarse_ = std::make_shared<PatchMatchStereo>(patchmatch::coarseParams(p));
    coarse_->intermediate_ = true;
  }
  coarse_->setParams(patchmatch::coarseParams(p));
  coarse_->level_scale_ = level_scale_ * p.coarse_scale;
  coarse_->right_planes_wanted_ = right_planes;
  ViewInput& coarse_left = scratch_->below_left;
  ViewInput& coarse_right = scratch_->below_right;
  bothViews(
      patchmatch::threadCount(p),
      [&] { patchmatch::downsampleView(left, p.coarse_scale, coarse_left); },
      [&] { patchmatch::downsampleView(right, p.coarse_scale, coarse_right); });
  steps_->lap("reducing the views");
  PatchMatchResult below = coarse_->compute(coarse_left, coarse_right);
  steps_->append(below.steps);
  return below;
}

PatchMatchResult PatchMatchStereo::upsampledResult(const ViewInput& left, const ViewInput& right) {
  using namespace patchmatch;
  const PatchMatchParams& p = params_;
  const int threads = threadCount(p);
  ViewState& lv = scratch_->left;
  preparePrior(left, p, lv);  // the images are the level below's alone
  steps_->lap("prior and locks");
  const PatchMatchResult below = levelBelow(left, right, false);
  PatchMatchResult result =
      resultFromLevelBelow(lv, below, p.coarse_scale, p.lr_check,
                           static_cast<float>(p.fill_confidence), planes_wanted_, threads);
  steps_->lap("up-sampling the result");
  return result;
}

PatchMatchResult PatchMatchStereo::compute(const ViewInput& left, const ViewInput& right) {
  const cv::Size size = left.image.size();
  patchmatch::checkViewInput(left, size, "left");
  patchmatch::checkViewInput(right, size, "right");
  if (!scratch_) scratch_ = std::make_shared<Scratch>();
  if (!steps_) steps_ = std::make_shared<Steps>();
  steps_->start(level_scale_);
  if (!intermediate_) params_ = configured_.forImage(size.width, size.height);
  const bool guided = hasCoarseStart(params_, size);
  PatchMatchResult result;
  if (guided && params_.search_scale > 1) {
    result = upsampledResult(left, right);
  } else {
    Level level = prepareLevel(left, right, guided);
    steps_->lap("preparing the views");
    if (guided) startFromLevelBelow(left, right, level);
    searchViews(level);
    result = postProcess(level);
  }
  result.steps = steps_->list;
  return result;
}

PatchMatchStereo::Level PatchMatchStereo::prepareLevel(const ViewInput& left,
                                                       const ViewInput& right, bool guided) {
  const PatchMatchParams& p = params_;
  Level level;
  level.size = left.image.size();
  level.guided = guided;
  level.threads = patchmatch::threadCount(p);
  bothViews(
      level.threads, [&] { patchmatch::prepareView(left, p, -1.f, scratch_->left); },
      [&] { patchmatch::prepareView(right, p, +1.f, scratch_->right); });
  level.iterations = guided ? p.fine_iterations : p.iterations;
  level.unmatched_bad = p.confidence_weighting && !scratch_->left.prior.empty();
  // Whether the full-size right view is searched: without a coarse start always; after one for
  // Bleyer's right view (fine_right_view) or a full-size left-right check (fine_lr_check).
  const bool two_views = p.view_propagation || p.lr_check;
  level.right_view = two_views && (!guided || p.fine_right_view || (p.lr_check && p.fine_lr_check));
  return level;
}

void PatchMatchStereo::startFromLevelBelow(const ViewInput& left, const ViewInput& right,
                                           Level& level) {
  using namespace patchmatch;
  const PatchMatchParams& p = params_;
  // Coarse start: its planes, up-sampled, are where this level's search begins.
  const PatchMatchResult coarse = levelBelow(left, right, level.right_view);
  setGuide(upsamplePlanes(coarse.planes, p.coarse_scale, level.size, level.threads), p,
           scratch_->left);
  // The coarse level has no left-right check, so without view propagation it has no right view.
  if (level.right_view && !coarse.right_planes.empty()) {
    setGuide(upsamplePlanes(coarse.right_planes, p.coarse_scale, level.size, level.threads), p,
             scratch_->right);
  }
  const cv::Mat1b below = checkLevelBelow(coarse, level);
  if (p.lr_check && !level.right_view) {
    if (below.empty()) {
      level.right_view = true;  // no view propagation below: only a full-size right view can check
    } else {
      level.inconsistent = upsampleMask(below, p.coarse_scale, level.size);
    }
  }
  if (p.skip_inconsistent && !below.empty()) skipInconsistent(below, level);
  steps_->lap("guide and masks");
}

cv::Mat1b PatchMatchStereo::checkLevelBelow(const PatchMatchResult& coarse,
                                            const Level& level) const {
  const PatchMatchParams& p = params_;
  // The level below's left-right check (its views, at lr_max_diff / coarse_scale), where this
  // level skips its inconsistent pixels or takes its mask as its own.
  const bool wanted = p.skip_inconsistent || (p.lr_check && !level.right_view);
  if (coarse.right_disparity.empty() || !wanted) return cv::Mat1b();
  const float max_diff = static_cast<float>(p.lr_max_diff / p.coarse_scale);
  return patchmatch::leftRightCheck(coarse.disparity, coarse.right_disparity, max_diff, {},
                                    level.unmatched_bad, level.threads);
}

void PatchMatchStereo::skipInconsistent(const cv::Mat1b& below, const Level& level) {
  if (!level.inconsistent.empty()) {
    // The fill replaces these pixels' disparity whatever the search finds (a third of the
    // full-size search on KITTI frame 0).
    patchmatch::leaveToFill(level.inconsistent, scratch_->left);
    return;
  }
  // This level's own check decides. Occluded or ambiguous below, they are mostly so here too,
  // and spreading their neighbours' planes serves them as well as searching them; but the border
  // of each region below, one of its pixels wide, is searched: coarse pixels straddle depth
  // edges, and skipping them would erode foreground objects by up to one coarse pixel (tested).
  cv::Mat1b interior;
  cv::erode(below, interior, cv::Mat());
  patchmatch::leaveToFill(patchmatch::upsampleMask(interior, params_.coarse_scale, level.size),
                          scratch_->left);
}

void PatchMatchStereo::searchViews(const Level& level) {
  using namespace patchmatch;
  const PatchMatchParams& p = params_;
  ViewState& lv = scratch_->left;
  ViewState& rv = scratch_->right;
  SearchOptions left_options, right_options;
  searchOptions(level, left_options, right_options);
  PlaneSearch left_search(p, lv, rv, left_options);
  PlaneSearch right_search(p, rv, lv, right_options);
  initialise(left_search, lv, p, 0);
  if (level.right_view) initialise(right_search, rv, p, 1);
  steps_->lap("initialisation");
  // The right view sweeps in the last `right_iterations` iterations only. It serves view
  // propagation and the left-right check; view propagation runs around its sweeps (left -> right
  // before, right -> left after), since in the other iterations the right view would only hand
  // the left view's own planes back.
  const int right_iterations =
      p.right_iterations < 0 ? level.iterations : std::min(p.right_iterations, level.iterations);
  for (int it = 0; it < level.iterations; ++it) {
    sweep(left_search, lv, p, it);
    steps_->lap("left sweep");
    if (!level.right_view || it < level.iterations - right_iterations) continue;
    searchRightView(level, left_search, right_search, right_options.refine, it);
  }
}

void PatchMatchStereo::searchOptions(const Level& level, patchmatch::SearchOptions& left,
                                     patchmatch::SearchOptions& right) const {
  const PatchMatchParams& p = params_;
  // The full-size level after a coarse start polishes the planes it was given: the left view
  // with a sub-pixel step (after random refinement if fine_refine); the right view, if searched,
  // by propagation alone unless fine_right_view.
  left.subpixel = level.guided && p.fine_subpixel;
  left.refine = !level.guided || p.fine_refine;
  right.refine = !level.guided || p.fine_right_view;
  // An intermediate level (1/2 size of three) refines its right view only with
  // intermediate_refine; else both views only propagate there.
  if (level.guided && intermediate_ && !p.intermediate_refine) right.refine = false;
  // Swept by propagation alone, the right view serves the left-right check only: a candidate
  // within half the check's threshold of its plane is not tried. (A quarter: `live`'s 1/2 right
  // sweep 13 % slower, every protocol the same within 0.002 px and 2 mm over four seeds; the
  // whole threshold: 27 % faster than a quarter, but a plain scene's check flags 5x as many
  // visible pixels.)
  if (!right.refine) right.tolerance = 0.5f * static_cast<float>(p.lr_max_diff);
}

void PatchMatchStereo::searchRightView(const Level& level, const patchmatch::PlaneSearch& left,
                                       const patchmatch::PlaneSearch& right, bool right_refines,
                                       int iteration) {
  using namespace patchmatch;
  const PatchMatchParams& p = params_;
  ViewState& lv = scratch_->left;
  ViewState& rv = scratch_->right;
  if (p.view_propagation) {
    // In a coarse start (every level of it, the coarsest too), the right view tries the left
    // planes in its sweep, with the windows the sweep builds anyway; Bleyer's view propagation
    // (a search without coarse start: the paper preset, plain PMS) builds one more per pixel,
    // before the sweep. (At the coarsest level the offers took 1.8 of its 32 ms on one thread,
    // every protocol within its seed noise.)
    if (level.guided || intermediate_) {
      offerView(lv, right, rv, p, true);
    } else {
      propagateView(lv, right, rv, p, true);
    }
    steps_->lap("view propagation to the right");
  }
  sweep(right, rv, p, iteration);
  steps_->lap("right sweep");
  // A right view swept by propagation alone holds the left planes it was offered or the level
  // below's, which that level's view propagation has handed to the left already: nothing new to
  // hand back (KITTI and Middlebury unchanged without it, a fifth of the level's work).
  if (p.view_propagation && right_refines) {
    propagateView(rv, left, lv, p, false);
    steps_->lap("view propagation to the left");
  }
}

PatchMatchResult PatchMatchStereo::postProcess(const Level& level) {
  using namespace patchmatch;
  const ViewState& lv = scratch_->left;
  const ViewState& rv = scratch_->right;
  PatchMatchResult result;
  result.disparity = disparityOf(lv, level.threads);
  if (planes_wanted_) result.planes = planeMap(lv, level.threads);
  if (level.right_view) {
    result.right_disparity = disparityOf(rv, level.threads);
    if (planes_wanted_ && right_planes_wanted_) result.right_planes = planeMap(rv, level.threads);
  }
  if (params_.lr_check) {
    result.inconsistent = consistencyCheck(result, level);
    fillHoles(lv, result.inconsistent.clone(), fillOptions(params_), result.disparity,
              level.threads);
  } else {
    result.inconsistent = cv::Mat1b(level.size, uchar(0));
  }
  markEmpty(result.disparity);
  steps_->lap("check and fill");
  return result;
}

cv::Mat1b PatchMatchStereo::consistencyCheck(const PatchMatchResult& result,
                                             const Level& level) const {
  const std::vector<uint8_t> keep = lockedToPrior(scratch_->left);
  if (level.inconsistent.empty()) {
    const float max_diff = static_cast<float>(params_.lr_max_diff);
    return patchmatch::leftRightCheck(result.disparity, result.right_disparity, max_diff, keep,
                                      level.unmatched_bad, level.threads);
  }
  cv::Mat1b inconsistent = level.inconsistent;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (keep[i]) inconsistent.data[i] = 0;  // the LiDAR measured it (leftRightCheck's keep)
  }
  return inconsistent;
}

}  // namespace lidar_stereo_fusion
