// Markdown tables of the accuracy protocols (eval/accuracy_protocols.h). ROS-free.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/eval/kitti_accumulated.h"
#include "lidar_stereo_fusion/eval/stereo_check.h"

namespace lidar_stereo_fusion {

/// Main table of a Middlebury layout: one row per method (mean of the scenes, region "all"), the
/// columns of formatDisparityTable plus raw coverage [%] (before the devkit fill) and the wall
/// time per scene [ms].
/// Then a per-scene table: MAE [px] and bad-2 [%] per scene.
std::string formatMiddleburyLayout(const LayoutScores<DisparityMetrics>& layout);

/// Main table of a KITTI layout: one row per method (mean over frames, region "all"), the columns
/// of formatDepthTable plus raw coverage [%] and the wall time per frame [ms].
std::string formatKittiLayout(const LayoutScores<DepthMetrics>& layout);

/// Per-region table: rows = methods, for each region (above, inside, edge, elsewhere) MAE [px]
/// and bad-2 [%] (Middlebury) or MAE [mm] and >3 px [%] (KITTI); a last row gives each region's
/// share of the reference pixels [%].
std::string formatMiddleburyRegions(const LayoutScores<DisparityMetrics>& layout);
std::string formatKittiRegions(const LayoutScores<DepthMetrics>& layout);

/// Depth-band table of a KITTI layout: rows = methods, MAE [mm] and RMSE [mm] over all reference
/// pixels and in the bands < 10 m, 10-30 m, >= 30 m of the reference depth; a last row gives each
/// band's share of the reference pixels [%].
std::string formatDepthBands(const LayoutScores<DepthMetrics>& layout);

/// Edge-sides table (eval/edge_sides.h): rows = methods, the method's own edge pixels with a
/// reference (summed over the items), the share of them where the reference has the near surface,
/// the far one, a value between or another, and the share of the method's squared error on them.
std::string formatEdgeSides(const LayoutScores<DisparityMetrics>& layout);
std::string formatEdgeSides(const LayoutScores<DepthMetrics>& layout);

/// How an accumulated reference was built (eval/kitti_accumulated.h), as a two-column table.
std::string formatAccumulatedReference(const kitti::AccumulatedDepth& reference);

/// The stereo check's rows, to follow formatAccumulatedReference's table (empty when max_diff_px
/// is 0: no check ran).
std::string formatStereoCheck(const StereoCheckCounts& counts, double max_diff_px);

}  // namespace lidar_stereo_fusion
