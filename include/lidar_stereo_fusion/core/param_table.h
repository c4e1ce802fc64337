// The one table of the algorithm's parameters (the fields of FusionParams). Each row gives the
// field its one name, group, range, unit and line of documentation (core/param_spec.h); the type
// and default are the field's own. The node's parameters have their table in ros/node_params.h.
//
// Everything else is derived from these rows or checked against them:
//   - each struct's validate(): the ranges (requireRanges), plus the checks between parameters;
//   - YAML (io/params_yaml.cpp), rosparam and dynamic_reconfigure (ros/ros_params.cpp) by name;
//   - cfg/Fusion.cfg, config/fusion.yaml and doc/parameters.md are generated from the table
//     (`rosrun lidar_stereo_fusion lsf_params --write <source dir>`; test_tools fails when a
//     committed file differs from what the table generates).
// Adding a parameter: a field in its struct, a row here, its use and its test; then regenerate.
#pragma once

#include "lidar_stereo_fusion/core/param_spec.h"
#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

/// Calls v(ParamSpec, field&) for every row of a group's struct, in table order.
template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, ProjectionParams>> visitParams(P&& p, V&& v) {
  const char* g = "projection";
  v(ParamSpec{"min_depth", g, above(0), "m",
              "Points closer than this along the optical axis are "
              "dropped"},
    p.min_depth);
  v(ParamSpec{"max_depth", g, above(0), "m", "Points farther than this are dropped (> min_depth)"},
    p.max_depth);
  v(ParamSpec{"remove_hidden_beside",
              g,
              {},
              "",
              "Drop the points the camera cannot see beside near objects (a LiDAR off the camera "
              "sees past their sides)"},
    p.remove_hidden_beside);
}

template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, BIParams>> visitParams(P&& p, V&& v) {
  const char* g = "bi";
  v(ParamSpec{"max_gap_px", g, atLeast(0), "px", "Scan-line completion does not bridge wider gaps"},
    p.max_gap_px);
  v(ParamSpec{"max_jump_disp", g, atLeast(0), "px", "Nor larger disparity jumps"}, p.max_jump_disp);
  v(ParamSpec{"step_fill",
              g,
              {},
              "",
              "Across a larger jump (within max_gap_px) each pixel takes the nearer point along "
              "the ring, the step in the middle (false: a gap, the paper)"},
    p.step_fill);
  v(ParamSpec{"max_disp_diff", g, atLeast(0), "px",
              "Algorithm 1 Maxdisp: foreground must exceed d by this"},
    p.max_disp_diff);
  v(ParamSpec{"max_color_diff", g, above(0), "", "Algorithm 1 Maxcolor: RGB L1 distance (0..765)"},
    p.max_color_diff);
  v(ParamSpec{"search_lines", g, atLeast(1), "",
              "Scan lines Algorithm 1 looks at up and down "
              "(paper: 1)"},
    p.search_lines);
  v(ParamSpec{"remove_parallax_hidden",
              g,
              {},
              "",
              "Fused methods: after Algorithm 1, clear a scan-line pixel that the nearer scan "
              "line next to it in its column more likely than not hides from the camera, for the "
              "images to decide (a LiDAR above the camera sees over top edges; false: the paper)"},
    p.remove_parallax_hidden);
  v(ParamSpec{"max_interp_rows", g, atLeast(1), "rows",
              "Eq. 3 does not bridge scan lines further apart"},
    p.max_interp_rows);
}

template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, BFParams>> visitParams(P&& p, V&& v) {
  const char* g = "bf";
  v(ParamSpec{"radius", g, within(0, BFParams::kMaxRadius), "px", "BF* half window"}, p.radius);
  v(ParamSpec{"sigma_space", g, atLeast(BFParams::kMinSigma), "px", "BF* spatial sigma"},
    p.sigma_space);
  v(ParamSpec{"sigma_range", g, atLeast(BFParams::kMinSigma), "px",
              "BF* disparity-range sigma (against the nearest point)"},
    p.sigma_range);
  v(ParamSpec{"min_support", g, atLeast(1), "",
              "BF*: pixels with fewer LiDAR neighbours stay empty (<= window pixels)"},
    p.min_support);
}

template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, PriorConfidenceParams>> visitParams(P&& p, V&& v) {
  const char* g = "confidence";
  v(ParamSpec{"edge_tolerance", g, atLeast(0), "px",
              "Residual two scan lines may differ by and still agree fully"},
    p.edge_tolerance);
  v(ParamSpec{"edge_sigma", g, above(0), "px",
              "Residual beyond the tolerance at which agreement is 1/e"},
    p.edge_sigma);
  v(ParamSpec{"max_surface_slope", g, atLeast(0), "px/row",
              "Steepest slope used to extend a surface from the lines above and below"},
    p.max_surface_slope);
  v(ParamSpec{"removed_factor", g, within(0, 1), "",
              "Agreement factor of a gap where Algorithm 1 removed a point"},
    p.removed_factor);
  v(ParamSpec{"near_rows", g, atLeast(0), "rows",
              "No distance decay within this many rows of a "
              "line"},
    p.near_rows);
  v(ParamSpec{"decay_rows", g, atLeast(0), "rows",
              "e-folding distance of the decay beyond near_rows (0 = off)"},
    p.decay_rows);
  v(ParamSpec{"hole_confidence", g, within(0, 1), "",
              "Confidence of the fused method's hole fill inside the LiDAR's view (0 = no fill)"},
    p.hole_confidence);
  v(ParamSpec{"top_extension_rows", g, atLeast(0), "rows",
              "The hole fill extends each column's top value this far up, at hole_confidence"},
    p.top_extension_rows);
}

template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, PatchMatchParams>> visitParams(P&& p, V&& v) {
  using PM = PatchMatchParams;
  const char* g = "patchmatch";
  v(ParamSpec{"window_radius", g, within(1, PM::kMaxWindowRadius), "px", "Support window (2r+1)^2"},
    p.window_radius);
  v(ParamSpec{"window_stride", g, atLeast(1), "px",
              "Window offsets are multiples of this (<= window_radius)"},
    p.window_stride);
  v(ParamSpec{"window_dyadic",
              g,
              {},
              "",
              "Window offsets 0, +-k, +-2k, +-4k, ... (7x7 samples of 17x17); false: every k-th"},
    p.window_dyadic);
  v(ParamSpec{"window_round",
              g,
              {},
              "",
              "Only the window samples within window_radius of the centre (a disc); false: the "
              "square"},
    p.window_round);
  v(ParamSpec{"weight_delta", g, above(0), "",
              "delta of the support weight exp(-|I_p - I_q|_1 / "
              "delta)"},
    p.weight_delta);
  v(ParamSpec{"image_smoothing", g, within(0, PM::kMaxImageSmoothing), "px",
              "Sigma of a 3x3 Gaussian on both images before matching (0 = off)"},
    p.image_smoothing);
  v(ParamSpec{"alpha", g, within(0, 1), "", "Colour weight (alpha + beta + gamma = 1)"}, p.alpha);
  v(ParamSpec{"beta", g, within(0, 1), "", "Gradient weight"}, p.beta);
  v(ParamSpec{"gamma", g, within(0, 1), "", "LiDAR disparity weight"}, p.gamma);
  v(ParamSpec{"lambda_col", g, above(0), "", "Colour truncation (RGB L1)"}, p.lambda_col);
  v(ParamSpec{"lambda_grad", g, above(0), "", "Gradient truncation"}, p.lambda_grad);
  v(ParamSpec{"lambda_disp", g, above(0), "px",
              "Disparity truncation; the cost where the prior is "
              "empty"},
    p.lambda_disp);
  v(ParamSpec{"iterations", g, within(0, PM::kMaxIterations), "",
              "PatchMatch sweeps (at the coarsest level of a coarse start)"},
    p.iterations);
  v(ParamSpec{"right_iterations", g, within(-1, PM::kMaxIterations), "",
              "Own sweeps of the right view, the last ones (-1 = every one, as Bleyer; not 0)"},
    p.right_iterations);
  v(ParamSpec{"slanted", g, {}, "", "Slanted windows (false: front-parallel)"}, p.slanted);
  v(ParamSpec{"init_from_prior", g, {}, "", "Initialise d from the LiDAR prior where it exists"},
    p.init_from_prior);
  v(ParamSpec{"init_normal_from_prior",
              g,
              {},
              "",
              "Slanted: initial normal from the prior's local slope"},
    p.init_normal_from_prior);
  v(ParamSpec{"use_lidar_bounds", g, {}, "", "Bound d by the scan lines above and below"},
    p.use_lidar_bounds);
  v(ParamSpec{"bound_margin", g, atLeast(0), "px", "Margin of the scan-line bounds"},
    p.bound_margin);
  v(ParamSpec{"min_refine_range", g, atLeast(0), "px", "Floor of Delta_d_max between scan lines"},
    p.min_refine_range);
  v(ParamSpec{"min_disparity", g, above(0), "px", "Image-wide search range, lower end"},
    p.min_disparity);
  v(ParamSpec{"max_disparity", g, above(0), "px",
              "Image-wide search range, upper end (> min_disparity)"},
    p.max_disparity);
  v(ParamSpec{"view_propagation", g, {}, "", "View propagation (Bleyer)"}, p.view_propagation);
  v(ParamSpec{"lr_check", g, {}, "", "Left-right check, hole filling, weighted median"},
    p.lr_check);
  v(ParamSpec{"lr_max_diff", g, above(0), "px", "Left-right check tolerance"}, p.lr_max_diff);
  v(ParamSpec{"median_radius", g, within(1, PM::kMaxMedianRadius), "px",
              "Half window of the weighted median over filled pixels"},
    p.median_radius);
  v(ParamSpec{"output_median", g, within(0, 5), "px",
              "Median of the fused output over this square (3 or 5; 0 = none): removes "
              "speckles, and with 5 lines under 3 px wide; LiDAR points stay"},
    p.output_median);
  v(ParamSpec{"mixed_edge_fraction", g, within(0, 1), "",
              "After the median: an edge pixel whose colour mixes in this fraction of a nearer "
              "neighbour's takes its depth (0 = off)"},
    p.mixed_edge_fraction);
  v(ParamSpec{"mixed_edge_contrast", g, atLeast(0), "",
              "Mixed edge pixels: smallest RGB L1 difference of the two surfaces' colours"},
    p.mixed_edge_contrast);
  v(ParamSpec{"confidence_weighting",
              g,
              {},
              "",
              "Weight the LiDAR term by the prior's confidence (false: the paper's cost)"},
    p.confidence_weighting);
  v(ParamSpec{"lock_confidence", g, atLeast(0), "",
              "Pixels with confidence >= this keep the prior and are not searched (> 1: none)"},
    p.lock_confidence);
  v(ParamSpec{"fill_confidence", g, within(0, 1), "",
              "Inconsistent pixels take the prior where its confidence is >= this"},
    p.fill_confidence);
  v(ParamSpec{"coarse_scale", g, within(1, PM::kMaxCoarseScale), "",
              "Coarse start: reduction factor between levels (1 = off)"},
    p.coarse_scale);
  v(ParamSpec{"coarse_levels", g, within(1, PM::kMaxCoarseLevels), "",
              "Coarse start: number of reduced levels"},
    p.coarse_levels);
  v(ParamSpec{"full_size_unbounded",
              g,
              {},
              "",
              "Search pixels without scan-line bounds at full size too (false: they keep the "
              "half-size plane)"},
    p.full_size_unbounded);
  v(ParamSpec{"unbounded_scale", g, atLeast(1), "",
              "Finest level (its reduction factor) searching pixels without scan-line bounds; 1 "
              "or a power of coarse_scale"},
    p.unbounded_scale);
  v(ParamSpec{"skip_inconsistent",
              g,
              {},
              "",
              "After the coarse start, unbounded pixels the level below marks inconsistent are "
              "not searched"},
    p.skip_inconsistent);
  v(ParamSpec{"search_scale", g, atLeast(1), "",
              "Finest level (its reduction factor) that searches at all; 1 or a power of "
              "coarse_scale"},
    p.search_scale);
  v(ParamSpec{"intermediate_refine",
              g,
              {},
              "",
              "Coarse start, the 1/2-size level of three: the right view refines and hands its "
              "planes back"},
    p.intermediate_refine);
  v(ParamSpec{"full_search_pixels", g, atLeast(0), "px",
              "An image of at most this many pixels is searched in full: search_scale 1, "
              "intermediate_refine true (0 = never)"},
    p.full_search_pixels);
  v(ParamSpec{"fine_iterations", g, within(1, PM::kMaxIterations), "",
              "Sweeps per larger level after the coarse start"},
    p.fine_iterations);
  v(ParamSpec{"fine_refine_range", g, above(0), "px",
              "Refinement range of every pixel after the coarse start"},
    p.fine_refine_range);
  v(ParamSpec{"fine_right_view",
              g,
              {},
              "",
              "Full size after the coarse start: refine the right view too (false: propagation)"},
    p.fine_right_view);
  v(ParamSpec{"fine_lr_check",
              g,
              {},
              "",
              "Full size after the coarse start: check against a full-size right view (false: "
              "the 1/2-size check, up-sampled)"},
    p.fine_lr_check);
  v(ParamSpec{"fine_subpixel",
              g,
              {},
              "",
              "The finest level that searches (full size, or 1/search_scale) after the coarse "
              "start: sub-pixel step on d ending the left view's search"},
    p.fine_subpixel);
  v(ParamSpec{"fine_refine",
              g,
              {},
              "",
              "After the coarse start: random refinement of the left view (false: propagation)"},
    p.fine_refine);
  v(ParamSpec{"num_threads", g, within(0, PM::kMaxThreads), "",
              "Worker threads (0 = all cores, or OMP_NUM_THREADS when set)"},
    p.num_threads);
  v(ParamSpec{"seed", g, atLeast(0), "", "Random seed (results do not depend on the thread count)"},
    p.seed);
}

/// Every row of FusionParams: method, then the groups in the order of the docs and YAML.
template <class P, class V>
void visitParamTable(P&& p, V&& v) {
  static_assert(std::is_same_v<std::decay_t<P>, FusionParams>);
  v(ParamSpec{"method", "", {}, "", "Fusion method", "fused_bi|fused_bf|pms|lidar_bi|lidar_bf"},
    p.method);
  visitParams(p.projection, v);
  visitParams(p.bi, v);
  visitParams(p.bf, v);
  visitParams(p.confidence, v);
  visitParams(p.patchmatch, v);
}

/// Throws std::invalid_argument("<owner>: <name> must be ...") at the first field of `p` outside
/// its row's range (validate() of each struct).
template <class P>
void requireRanges(const char* owner, const P& p) {
  visitParams(p, RangeChecker{owner});
}

}  // namespace lidar_stereo_fusion
