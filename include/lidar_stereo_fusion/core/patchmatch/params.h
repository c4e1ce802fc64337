// What the PatchMatch steps share: the parameters (PatchMatchParams, one row each in
// core/param_table.h), the inputs of one view (ViewInput) and the result (PatchMatchResult). The
// steps' headers include this, not the driver's core/patchmatch.h.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {

struct PatchMatchParams {
  // Named limits of the ranges in core/param_table.h (kernels size their buffers by them).
  static constexpr int kMaxWindowRadius = 50;  ///< [px] window_radius
  static constexpr int kMaxMedianRadius = 50;  ///< [px] median_radius
  static constexpr int kMaxIterations = 100;   ///< iterations, right_iterations, fine_iterations
  static constexpr int kMaxCoarseScale = 16;   ///< coarse_scale
  static constexpr int kMaxCoarseLevels = 4;   ///< coarse_levels
  static constexpr int kMaxThreads = 256;      ///< num_threads (more crashes libgomp)
  static constexpr double kMaxImageSmoothing = 5.0;  ///< [px] image_smoothing

  /// Support window (2r+1)^2 [px]. The paper found size ~10 best for its fused cost, ~40 for plain
  /// PMS; with confidence weighting the images lead where the LiDAR is absent, and need plain
  /// stereo's support there: 17x17 (sampled every 2nd pixel: 9x9 points) won on every protocol.
  int window_radius = 8;
  /// Window offsets used are the multiples of k within the radius (2: -8, -6, ..., 8), or with
  /// window_dyadic 0, +-k, +-2k, +-4k, ... within the radius (2: -8, -4, -2, 0, 2, 4, 8).
  int window_stride = 2;
  /// Dyadic window sampling (above): dense at the centre, where the support weights are high,
  /// sparse at the rim; 7x7 instead of 9x9 samples for the 17x17 window, for 40 % less cost work.
  bool window_dyadic = true;
  /// Round window: of the offsets' grid, only the samples within window_radius of the centre (a
  /// disc; 29 of the 7x7 dyadic samples of 17x17: the 5x5 within +-4 and the 4 axis ends at 8).
  /// The square's corners are the samples farthest from the centre; the cost kernel takes 16
  /// samples a step, so 29 samples are 2 steps instead of 4 (about 20 % of the frame's time). On
  /// the accuracy protocols: KITTI hold-out MAE +2 %, Middlebury within 2 % (README).
  bool window_round = true;
  double weight_delta = 10.0;  ///< delta of w = exp(-|I_p - I_p'|_1 / delta)
  /// [px] sigma of a 3x3 Gaussian applied to both images before matching (0 = off). Linear
  /// interpolation of the other view at a sub-pixel match attenuates fine texture, which pulls
  /// the cost's minimum toward whole-pixel disparities ("pixel locking"); a band-limited image
  /// interpolates nearly exactly. The paper preset: 0.
  double image_smoothing = 1.0;
  /// Weights of colour, gradient and LiDAR terms, alpha + beta + gamma = 1. The paper: 0.1, 0,
  /// 0.9. Default: gamma 0.9 where the LiDAR is sure, and an image term of Bleyer's mix (1 : 9
  /// colour : gradient), which confidence weighting renormalises to full weight without LiDAR.
  double alpha = 0.01;
  double beta = 0.09;
  double gamma = 0.9;
  double lambda_col = 10.0;  ///< colour truncation (RGB L1 distance, 0..765 scale)
  double lambda_grad = 2.0;  ///< gradient truncation
  double lambda_disp = 2.0;  ///< disparity truncation [px]; also the cost where the prior is empty
  int iterations = 2;
  /// Sweeps of the right view (the last min(k, iterations)); -1 = all (Bleyer). The right view
  /// serves view propagation and the left-right check and receives the left view's refined planes
  /// by view propagation before each of its sweeps; one sweep was as accurate on KITTI and
  /// Middlebury as three and saves ~40 % of the time.
  int right_iterations = 1;
  bool slanted = true;                 ///< false: front-parallel windows (n = (0, 0, 1))
  bool init_from_prior = true;         ///< d = prior where it exists, else random
  bool init_normal_from_prior = true;  ///< slanted: initial normal from the prior's local slope
  bool use_lidar_bounds = true;        ///< limit d to the scan lines above/below (+- bound_margin)
  double bound_margin = 1.0;           ///< [px]
  double min_refine_range = 0.5;       ///< floor of Delta_d_max between scan lines [px]
  double min_disparity = 1.0;          ///< image-wide search range [px]
  double max_disparity = 192.0;        ///< [px]
  bool view_propagation = true;
  bool lr_check = true;      ///< left-right consistency + hole filling + weighted median
  double lr_max_diff = 1.0;  ///< [px]
  /// Half window [px] of the weighted median over filled pixels (sampled every 2nd pixel). Plain
  /// PMS uses its matching window (Bleyer); the fused method 11x11, which was as accurate as its
  /// 17x17 matching window on every protocol and cheaper.
  int median_radius = 5;
  /// Median of the fused output over size x size pixels (3 or 5; 0 = none): output_median.h.
  int output_median = 3;
  /// After the median, edge pixels whose colour mixes in at least this fraction of a nearer
  /// neighbour's take its disparity (0 = off): mixed_edges.h.
  double mixed_edge_fraction = 0.75;
  /// Smallest RGB L1 contrast between the two surfaces for that [0..765].
  double mixed_edge_contrast = 60.0;
  /// Weight the LiDAR term by the prior's confidence and renormalise the image term where it fades
  /// (patchmatch/cost.h); false = the paper's cost (gamma everywhere the prior has a value).
  bool confidence_weighting = true;
  /// Pixels whose prior confidence is >= this keep the prior's plane and are not searched (the
  /// LiDAR is sure there; > 1 = search every pixel). Only with confidence_weighting.
  double lock_confidence = 0.5;
  /// Inconsistent pixels (left-right check) take the prior where its confidence is >= this.
  double fill_confidence = 0.5;
  /// Coarse start (patchmatch/coarse_to_fine.h): the search first runs on images reduced by
  /// coarse_scale^coarse_levels (1 = off), then at each larger level `fine_iterations` sweeps start
  /// from the planes of the level below; a view that refines there refines every searched pixel
  /// from +-fine_refine_range (instead of half the image's disparity range, or the scan lines'
  /// range; 0.5 or 0.25 px: synthetic slanted planes 0.055 px off instead of 0.045).
  int coarse_scale = 2;
  int coarse_levels = 2;
  /// Whether the pixels without scan-line bounds (no LiDAR above and below) are searched at full
  /// size too (the default); false: they keep the plane of the level below (half size), refined
  /// but not propagated, in the left view only: ~1.4x faster on KITTI, 0.1-0.2 px less precise
  /// where only the images decide (above the LiDAR's field of view).
  bool full_size_unbounded = true;
  /// The finest level, as its reduction factor, at which the pixels without scan-line bounds are
  /// searched: 1 = every level (the default); coarse_scale (2) = up to 1/2 size, after which they
  /// take the 1/2-size plane as it is, with no window (above the LiDAR's field of view, a third
  /// of a KITTI image and three quarters of its searched pixels); coarse_scale^2 = up to 1/4
  /// size. Between the presets: full-size precision inside the LiDAR's view, about 0.7 of the
  /// default's PatchMatch on KITTI. 1 or a power of coarse_scale up to the coarsest level.
  int unbounded_scale = 1;
  /// After a coarse start: the pixels without scan-line bounds that the left-right check of the
  /// level below marks inconsistent (occluded or ambiguous) are not searched; each takes the
  /// plane before it in the row, as the hole filling would. At full size the fill replaces them
  /// anyway (a third of the full-size search on KITTI frame 0); at 1/2 size, where the level's
  /// own check decides, only the interior of the regions below (the synthetic street's whole
  /// image 359 mm instead of 416, three seeds). false: every such pixel is searched.
  bool skip_inconsistent = true;
  /// The finest level, as its reduction factor, that searches at all: 1 = full size (the
  /// default); coarse_scale (2) = the 1/2-size level searches, checks left against right and fills
  /// its holes, and full size only up-samples its result: planes evaluated at full size, the
  /// prior's plane where the prior is locked or fills an inconsistent pixel, the level's filled
  /// disparity (times coarse_scale) on its other inconsistent pixels. The `live` preset (2):
  /// about 0.45 of the default's PatchMatch on KITTI. 1 or a power of coarse_scale up to the
  /// coarsest level.
  int search_scale = 1;
  /// Intermediate levels of the coarse start (the 1/2-size level of three): the right view
  /// refines its planes at random from +-fine_refine_range, after the left view's planes were
  /// offered to it, and hands them back to the left view (true, as Bleyer); false: both views
  /// only propagate there, the right view for the left-right check (about a fifth of the
  /// default's PatchMatch on KITTI, and Middlebury 16 rows 0.017 px worse on three seeds: off in
  /// the `live` preset only).
  bool intermediate_refine = true;
  /// An image of at most this many pixels is searched in full: search_scale 1 and
  /// intermediate_refine true whatever they say (0 = never; forImage()). Those two cut the search
  /// to keep a sensor's rate at its image size; a small image needs no cut. The `live` preset:
  /// 200000, so Middlebury's quarter size (450x375) is searched as the default searches it, in
  /// about 37 ms on two cores (the default's time grows with the pixels: KITTI's 465,750 about
  /// 100 ms), less than `live` takes for KITTI, which it still searches at 1/2 size, as the rig.
  int full_search_pixels = 0;
  int fine_iterations = 1;
  double fine_refine_range = 1.0;  ///< [px]
  /// Full-size level of a coarse start only: whether the right view is searched with refinement
  /// and hands its planes back to the left view (Bleyer). false: it is searched only for a
  /// full-size left-right check (fine_lr_check), by propagation alone: the planes of the level
  /// below, spread by propagation, suffice for the check, and it would hand back only the left's
  /// own planes or the level below's.
  bool fine_right_view = false;
  /// Full-size level of a coarse start, unless fine_right_view: where the left-right check runs.
  /// false: it compares the two views of the level below (1/2 size, lr_max_diff / coarse_scale)
  /// and its mask, up-sampled, marks the full-size pixels; no full-size right view is searched
  /// (a fifth of the time; KITTI and Middlebury within 2 % either way).
  /// true: against a full-size right view swept by propagation alone.
  bool fine_lr_check = false;
  /// The finest level that searches after a coarse start (full size, or the 1/search_scale level
  /// when search_scale > 1) only: a sub-pixel step on the left view's d
  /// (patchmatch/propagation.h), after the random refinement if fine_refine; random refinement
  /// alone would need more candidates for the same precision (synthetic planes: 0.045 px mean
  /// error with the step, 0.055 px without).
  bool fine_subpixel = true;
  /// Every level after the coarse start (1/2 and full size): random refinement of the left view
  /// from +-fine_refine_range (then, at full size, the sub-pixel step). false: the left view takes
  /// planes by propagation and from the right view (which refines at 1/2 size), and at full size
  /// the sub-pixel step alone polishes them (half the cost evaluations of the levels; KITTI and
  /// Middlebury within a few per cent either way).
  bool fine_refine = false;
  int num_threads = 0;  ///< 0 = all cores, or OMP_NUM_THREADS when set (at most 256)
  uint64_t seed = 42;
  /// The cost kernels' instructions (patchmatch/simd.h): every path gives the same result, only
  /// the speed differs. Not a tunable parameter (not in the parameter table): a value the caller
  /// gives, by default the widest this CPU runs; the tools take it from LSF_SIMD (io/simd_env.h).
  /// Each object keeps its own: two pipelines in one process cannot change each other's.
  SimdPath simd_path = widestSimdPath();
  void validate() const;
  /// The parameters that search an image of width x height (full_search_pixels).
  PatchMatchParams forImage(int width, int height) const;
};
// The SIMD kernels size their stack buffers by cost_kernel.h's limit.
static_assert(PatchMatchParams::kMaxWindowRadius == patchmatch::kMaxWindowRadius,
              "window_radius's range and the kernels' buffers must agree");

/// Wall time of one step of PatchMatchStereo::compute, named by its level ("1/4", "1/2", "1/1")
/// and what it does (e.g. "1/2 left sweep"): the per-stage table of fusion_benchmark.
struct PatchMatchStep {
  std::string name;
  double ms = 0;
};

/// Output of PatchMatch for the left view.
struct PatchMatchResult {
  cv::Mat1f disparity;        ///< dense left disparity [px], 0 where nothing could be filled
  cv::Mat1f right_disparity;  ///< right view disparity [px] (when computed)
  cv::Mat1b inconsistent;     ///< 255 where the left-right check failed (then filled)
  cv::Mat3f planes;           ///< per-pixel plane (a, b, c): d = a x + b y + c
  cv::Mat3f right_planes;     ///< the same for the right view (when computed)
  std::vector<PatchMatchStep> steps;  ///< the steps' wall times, coarsest level first
};

/// Inputs of one view.
struct ViewInput {
  ViewInput() = default;
  ViewInput(cv::Mat image_, cv::Mat1f prior_ = cv::Mat1f(), ScanLineBounds bounds_ = {},
            cv::Mat1f confidence_ = cv::Mat1f())
      : image(std::move(image_)),
        prior(std::move(prior_)),
        bounds(std::move(bounds_)),
        confidence(std::move(confidence_)) {}

  cv::Mat image;          ///< BGR CV_8UC3 (or grey CV_8UC1) rectified image
  cv::Mat1f prior;        ///< up-sampled LiDAR disparity of this view, 0 = empty (may be empty())
  ScanLineBounds bounds;  ///< search bounds from the scan lines (may be empty())
  cv::Mat1f confidence;   ///< confidence of the prior in [0, 1] (may be empty(): 1 where the
                          ///< prior has a value)
};

}  // namespace lidar_stereo_fusion
