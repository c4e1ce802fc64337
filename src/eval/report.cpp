// Text tables of depth metrics and stage timings.
#include "lidar_stereo_fusion/eval/report.h"

#include <algorithm>
#include <cstdio>

namespace lidar_stereo_fusion {

namespace table {

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string row(const std::vector<std::string>& cells) {
  std::string line = "|";
  for (const std::string& c : cells) line += " " + c + " |";
  return line + "\n";
}

std::string separator(size_t columns) {
  std::string line = "|";
  for (size_t i = 0; i < columns; ++i) line += "---|";
  return line + "\n";
}

}  // namespace table

namespace {

using table::format;
using table::row;
using table::separator;

}  // namespace

std::string formatDepthTable(const std::vector<DepthRow>& rows) {
  const std::vector<std::string> header = {"",           "MAE mm",  "RMSE mm", "iMAE 1/km",
                                           "iRMSE 1/km", ">2 px %", ">3 px %", ">5 px %",
                                           "coverage %", "pixels"};
  std::string out = row(header) + separator(header.size());
  for (const DepthRow& r : rows) {
    const DepthMetrics& m = r.metrics;
    out += row(
        {r.name, format("%.0f", m.mae_mm), format("%.0f", m.rmse_mm), format("%.2f", m.imae_per_km),
         format("%.2f", m.irmse_per_km), format("%.2f", 100 * m.bad2), format("%.2f", 100 * m.bad3),
         format("%.2f", 100 * m.bad5), format("%.1f", 100 * m.coverage), std::to_string(m.count)});
  }
  return out;
}

std::string formatDisparityTable(const std::vector<DisparityRow>& rows) {
  const std::vector<std::string> header = {"",        "MAE px",  "RMSE px",    ">1 px %", ">2 px %",
                                           ">3 px %", ">5 px %", "coverage %", "pixels"};
  std::string out = row(header) + separator(header.size());
  for (const DisparityRow& r : rows) {
    const DisparityMetrics& m = r.metrics;
    out += row({r.name, format("%.3f", m.mae_px), format("%.3f", m.rmse_px),
                format("%.2f", 100 * m.bad1), format("%.2f", 100 * m.bad2),
                format("%.2f", 100 * m.bad3), format("%.2f", 100 * m.bad5),
                format("%.1f", 100 * m.coverage), std::to_string(m.count)});
  }
  return out;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string formatTimingSummary(const std::vector<FrameStats>& stats) {
  struct Stage {
    const char* name;
    double FrameStats::*field;
  };
  const Stage stages[] = {{"projection", &FrameStats::projection_ms},
                          {"up-sampling", &FrameStats::upsampling_ms},
                          {"PatchMatch", &FrameStats::patchmatch_ms},
                          {"depth", &FrameStats::depth_ms},
                          {"total", &FrameStats::total_ms}};
  std::string out = row({"stage", "mean ms", "median ms"}) + separator(3);
  for (const Stage& stage : stages) {
    std::vector<double> values;
    for (const FrameStats& s : stats) values.push_back(s.*(stage.field));
    double mean = 0.0;
    for (double v : values) mean += v;
    mean = values.empty() ? 0.0 : mean / values.size();
    out += row({stage.name, format("%.1f", mean), format("%.1f", median(values))});
  }
  double in_front = 0, projected = 0, removed = 0, prior = 0, output = 0;
  for (const FrameStats& s : stats) {
    in_front += s.points_in_front;
    projected += s.points_projected;
    removed += s.points_removed;
    prior += s.prior_coverage;
    output += s.output_coverage;
  }
  const double n = std::max<size_t>(1, stats.size());
  out += "\nframes " + std::to_string(stats.size()) + "; per frame (mean): points in front " +
         format("%.0f", in_front / n) + ", in image " + format("%.0f", projected / n) +
         ", removed by Algorithm 1 " + format("%.0f", removed / n) + ", prior coverage " +
         format("%.1f", 100 * prior / n) + " %, output coverage " +
         format("%.1f", 100 * output / n) + " %\n";
  return out;
}

}  // namespace lidar_stereo_fusion
