// The progress bar of long runs.
#include "lidar_stereo_fusion/io/progress.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <stdexcept>

namespace lidar_stereo_fusion {

namespace {

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

}  // namespace

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
