// The one list of the algorithm's parameters (the fields of lidar_stereo_fusion::FusionParams).
//
// Each parameter has ONE name, used everywhere: the YAML key (config/fusion.yaml, the tools'
// --params), the ROS parameter in the nodelet's private namespace (~window_radius), the
// dynamic_reconfigure parameter (cfg/Fusion.cfg: `dynparam set /fusion/fusion window_radius 5`)
// and the README's table. The group only orders them (YAML comments, dynamic_reconfigure groups,
// README rows); the old grouped spellings (`patchmatch: {window_radius: 5}`,
// ~patchmatch/window_radius, patchmatch_window_radius) are read as deprecated aliases.
//
// Defaults and validation stay in the core structs (FusionParams::validate()). YAML reading and
// writing (io/params_yaml.cpp) and the ROS layer (ros/ros_params.cpp) walk this table;
// test_params_table checks cfg/Fusion.cfg, config/fusion.yaml and README.md against it, so a field
// added here must be added there too (and the test says where).
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

/// Name and group of one parameter.
struct ParamName {
  const char* name;   ///< the one name (unique across groups)
  const char* group;  ///< "" for method; projection, bi, bf, confidence, patchmatch
};

/// Calls v(ParamName, field&) for every field of `p` (FusionParams, const or not), in the order
/// of the README and cfg/Fusion.cfg. Field types: Method, double, int, bool, uint64_t (seed).
template <class P, class V>
void visitParamTable(P& p, V&& v) {
  v(ParamName{"method", ""}, p.method);
  auto& pr = p.projection;
  v(ParamName{"min_depth", "projection"}, pr.min_depth);
  v(ParamName{"max_depth", "projection"}, pr.max_depth);
  auto& bi = p.bi;
  v(ParamName{"max_gap_px", "bi"}, bi.max_gap_px);
  v(ParamName{"max_jump_disp", "bi"}, bi.max_jump_disp);
  v(ParamName{"max_disp_diff", "bi"}, bi.max_disp_diff);
  v(ParamName{"max_color_diff", "bi"}, bi.max_color_diff);
  v(ParamName{"search_lines", "bi"}, bi.search_lines);
  v(ParamName{"max_interp_rows", "bi"}, bi.max_interp_rows);
  auto& bf = p.bf;
  v(ParamName{"radius", "bf"}, bf.radius);
  v(ParamName{"sigma_space", "bf"}, bf.sigma_space);
  v(ParamName{"sigma_range", "bf"}, bf.sigma_range);
  v(ParamName{"min_support", "bf"}, bf.min_support);
  auto& c = p.confidence;
  v(ParamName{"edge_tolerance", "confidence"}, c.edge_tolerance);
  v(ParamName{"edge_sigma", "confidence"}, c.edge_sigma);
  v(ParamName{"max_surface_slope", "confidence"}, c.max_surface_slope);
  v(ParamName{"removed_factor", "confidence"}, c.removed_factor);
  v(ParamName{"near_rows", "confidence"}, c.near_rows);
  v(ParamName{"decay_rows", "confidence"}, c.decay_rows);
  v(ParamName{"hole_confidence", "confidence"}, c.hole_confidence);
  auto& m = p.patchmatch;
  const char* pm = "patchmatch";
  v(ParamName{"window_radius", pm}, m.window_radius);
  v(ParamName{"window_stride", pm}, m.window_stride);
  v(ParamName{"window_dyadic", pm}, m.window_dyadic);
  v(ParamName{"window_round", pm}, m.window_round);
  v(ParamName{"weight_delta", pm}, m.weight_delta);
  v(ParamName{"image_smoothing", pm}, m.image_smoothing);
  v(ParamName{"alpha", pm}, m.alpha);
  v(ParamName{"beta", pm}, m.beta);
  v(ParamName{"gamma", pm}, m.gamma);
  v(ParamName{"lambda_col", pm}, m.lambda_col);
  v(ParamName{"lambda_grad", pm}, m.lambda_grad);
  v(ParamName{"lambda_disp", pm}, m.lambda_disp);
  v(ParamName{"iterations", pm}, m.iterations);
  v(ParamName{"right_iterations", pm}, m.right_iterations);
  v(ParamName{"slanted", pm}, m.slanted);
  v(ParamName{"init_from_prior", pm}, m.init_from_prior);
  v(ParamName{"init_normal_from_prior", pm}, m.init_normal_from_prior);
  v(ParamName{"use_lidar_bounds", pm}, m.use_lidar_bounds);
  v(ParamName{"bound_margin", pm}, m.bound_margin);
  v(ParamName{"min_refine_range", pm}, m.min_refine_range);
  v(ParamName{"min_disparity", pm}, m.min_disparity);
  v(ParamName{"max_disparity", pm}, m.max_disparity);
  v(ParamName{"view_propagation", pm}, m.view_propagation);
  v(ParamName{"lr_check", pm}, m.lr_check);
  v(ParamName{"lr_max_diff", pm}, m.lr_max_diff);
  v(ParamName{"median_radius", pm}, m.median_radius);
  v(ParamName{"confidence_weighting", pm}, m.confidence_weighting);
  v(ParamName{"lock_confidence", pm}, m.lock_confidence);
  v(ParamName{"fill_confidence", pm}, m.fill_confidence);
  v(ParamName{"coarse_scale", pm}, m.coarse_scale);
  v(ParamName{"coarse_levels", pm}, m.coarse_levels);
  v(ParamName{"full_size_unbounded", pm}, m.full_size_unbounded);
  v(ParamName{"unbounded_scale", pm}, m.unbounded_scale);
  v(ParamName{"skip_inconsistent", pm}, m.skip_inconsistent);
  v(ParamName{"search_scale", pm}, m.search_scale);
  v(ParamName{"intermediate_refine", pm}, m.intermediate_refine);
  v(ParamName{"fine_iterations", pm}, m.fine_iterations);
  v(ParamName{"fine_refine_range", pm}, m.fine_refine_range);
  v(ParamName{"fine_right_view", pm}, m.fine_right_view);
  v(ParamName{"fine_lr_check", pm}, m.fine_lr_check);
  v(ParamName{"fine_subpixel", pm}, m.fine_subpixel);
  v(ParamName{"fine_refine", pm}, m.fine_refine);
  v(ParamName{"num_threads", pm}, m.num_threads);
  v(ParamName{"seed", pm}, m.seed);
}

/// One parameter with its type and its default (FusionParams{}) as text.
struct ParamInfo {
  std::string name, group;
  std::string type;           ///< "string", "double", "int" or "bool"
  std::string default_value;  ///< as YAML would write it (doubles shortest round-trip)
};

/// Every parameter, in table order.
std::vector<ParamInfo> paramTable();

/// The groups, in table order ("projection", "bi", "bf", "confidence", "patchmatch").
std::vector<std::string> paramGroups();

/// Shortest text that reads back to the same double, always with a '.' or exponent ("200.0").
std::string formatParamDouble(double v);

}  // namespace lidar_stereo_fusion
