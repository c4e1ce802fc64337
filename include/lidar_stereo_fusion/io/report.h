// Text tables for tools and tests: depth metrics per method or frame, stage timings, and a
// progress bar for long runs. ROS-free.
#pragma once

#include <iosfwd>
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

/// A one-line progress bar ("[=====>    ] 5/11 name  1.2 s/frame"), redrawn in place with '\r'
/// when `interactive` (a terminal), otherwise one line per update.
class ProgressBar {
 public:
  ProgressBar(std::ostream& out, int total, bool interactive, int width = 30);
  /// Shows `done` of `total` finished, with `note` (e.g. the current frame) after the bar, the
  /// seconds per item so far and the estimated time left.
  void update(int done, const std::string& note);
  /// Ends the line (interactive mode).
  void finish();

 private:
  std::ostream& out_;
  int total_;
  bool interactive_;
  int width_;
  double start_s_;
  bool open_line_ = false;
};

}  // namespace lidar_stereo_fusion
