// Text tables for tools and tests: depth metrics per method or frame and stage timings (the
// progress bar of long runs is io/progress.h). ROS-free.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

/// Markdown table pieces shared by the report writers.
namespace table {
/// `v` printed with the printf format `fmt` (one double conversion).
std::string format(const char* fmt, double v);
/// "| a | b | ... |" and a newline.
std::string row(const std::vector<std::string>& cells);
/// "|---|---|...|" for `columns` columns and a newline.
std::string separator(size_t columns);
}  // namespace table

/// One row of a depth-metrics table (a frame, or a method's mean over frames).
struct DepthRow {
  std::string name;
  DepthMetrics metrics;
};
/// Columns: name, MAE [mm], RMSE [mm], iMAE [1/km], iRMSE [1/km], >2/>3/>5 px [%], coverage [%],
/// pixels. One line per row, Markdown table syntax.
std::string formatDepthTable(const std::vector<DepthRow>& rows);

/// One row of a disparity-metrics table (Middlebury).
struct DisparityRow {
  std::string name;
  DisparityMetrics metrics;
};
/// Columns: name, MAE [px], RMSE [px], >1/>2/>3/>5 px [%], coverage [%], pixels. Markdown.
std::string formatDisparityTable(const std::vector<DisparityRow>& rows);

/// Median of `values` (mean of the middle two for an even count); 0 for none.
double median(std::vector<double> values);

/// Per-stage wall time over frames: mean and median [ms] of projection, up-sampling, PatchMatch,
/// depth and total, plus the mean point counts and coverages. Markdown.
std::string formatTimingSummary(const std::vector<FrameStats>& stats);

}  // namespace lidar_stereo_fusion
