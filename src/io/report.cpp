// Text tables and a progress bar.
#include "lidar_stereo_fusion/io/report.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <stdexcept>

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

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

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

ProgressBar::ProgressBar(std::ostream& out, int total, bool interactive, int width)
    : out_(out), total_(total), interactive_(interactive), width_(width), start_s_(nowSeconds()) {
  if (total < 0 || width < 1) throw std::invalid_argument("ProgressBar: total < 0 or width < 1");
}

void ProgressBar::update(int done, const std::string& note) {
  const int clamped = std::clamp(done, 0, total_);
  const int filled = total_ > 0 ? width_ * clamped / total_ : width_;
  std::string bar(static_cast<size_t>(filled), '=');
  if (filled < width_) bar += '>';
  bar.resize(static_cast<size_t>(width_), ' ');
  const double elapsed = nowSeconds() - start_s_;
  std::string line =
      "[" + bar + "] " + std::to_string(clamped) + "/" + std::to_string(total_) + " " + note;
  if (clamped > 0) line += "  " + format("%.2f", elapsed / clamped) + " s/frame";
  // The time left at the mean rate so far.
  if (clamped > 0 && clamped < total_) {
    line += ", ETA " + format("%.0f", elapsed / clamped * (total_ - clamped)) + " s";
  }
  if (interactive_) {
    out_ << "\r" << line << "\033[K" << std::flush;  // \033[K clears the rest of the line
    open_line_ = true;
  } else {
    out_ << line << "\n" << std::flush;
  }
}

void ProgressBar::finish() {
  if (open_line_) out_ << "\n" << std::flush;
  open_line_ = false;
}

}  // namespace lidar_stereo_fusion
