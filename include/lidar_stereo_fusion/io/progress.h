// A progress bar for the tools' long runs. ROS-free.
#pragma once

#include <iosfwd>
#include <string>

namespace lidar_stereo_fusion {

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
