// kitti_to_bag's choice of frames and their stamps (see kitti_bag_frames.h).
#include "kitti_bag_frames.h"

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {

namespace fs = std::filesystem;

namespace {

/// Timestamps [s] of a KITTI timestamps file indexed by frame (= line) number; a blank line (a
/// dropped sample, NaN from kitti::readTimestamps) gives std::nullopt.
std::vector<std::optional<double>> readTimestampsByFrame(const fs::path& path) {
  std::vector<std::optional<double>> by_frame;
  for (const double stamp : kitti::readTimestamps(path.string())) {
    by_frame.push_back(std::isfinite(stamp) ? std::optional<double>(stamp) : std::nullopt);
  }
  return by_frame;
}

std::optional<double> stampOf(const std::vector<std::optional<double>>& stamps, size_t frame) {
  return frame < stamps.size() ? stamps[frame] : std::nullopt;
}

/// Names (file stems) of the files with `extension` in `dir`, sorted; empty if no such folder.
std::set<std::string> stemsIn(const fs::path& dir, const std::string& extension) {
  std::set<std::string> stems;
  if (!fs::is_directory(dir)) return stems;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == extension) {
      stems.insert(entry.path().stem().string());
    }
  }
  return stems;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

}  // namespace

namespace {

/// Names the files that cannot form a frame (e.g. LiDAR-only frames between the stereo frames).
void reportIncomplete(const fs::path& drive, const std::vector<kitti::Frame>& complete) {
  std::set<std::string> all = stemsIn(drive / "image_02" / "data", ".png");
  const std::set<std::string> right = stemsIn(drive / "image_03" / "data", ".png");
  const std::set<std::string> sweeps = stemsIn(drive / "velodyne_points" / "data", ".bin");
  all.insert(right.begin(), right.end());
  all.insert(sweeps.begin(), sweeps.end());
  std::set<std::string> complete_names;
  for (const auto& f : complete) complete_names.insert(f.name);
  std::vector<std::string> incomplete;
  for (const auto& name : all) {
    if (!complete_names.count(name)) incomplete.push_back(name);
  }
  if (!incomplete.empty()) {
    std::cerr << "kitti_to_bag: skipping " << incomplete.size()
              << " frame(s) without all of image_02, image_03 and a Velodyne sweep: "
              << joined(incomplete) << "\n";
  }
}

/// The drive's image and sweep stamps by frame, and the sweep starts when the drive has them.
struct DriveStampFiles {
  std::vector<std::optional<double>> images, sweeps, starts;
  bool have_end = false;  ///< sweeps stamped at their end (timestamps_end.txt)
};

/// Sweep stamps: the sweep end (timestamps_end.txt), as velodyne_driver stamps a scan at its last
/// packet; without that file, the forward-facing instant (timestamps.txt, mid-sweep).
DriveStampFiles readStampFiles(const fs::path& drive) {
  const fs::path velo_dir = drive / "velodyne_points";
  DriveStampFiles d;
  d.have_end = fs::is_regular_file(velo_dir / "timestamps_end.txt");
  d.images = readTimestampsByFrame(drive / "image_02" / "timestamps.txt");
  d.sweeps =
      readTimestampsByFrame(velo_dir / (d.have_end ? "timestamps_end.txt" : "timestamps.txt"));
  if (fs::is_regular_file(velo_dir / "timestamps_start.txt")) {
    d.starts = readTimestampsByFrame(velo_dir / "timestamps_start.txt");
  }
  if (!d.have_end) {
    std::cerr << "kitti_to_bag: no velodyne_points/timestamps_end.txt: stamping sweeps at the "
                 "forward-facing instant (timestamps.txt)\n";
  }
  return d;
}

}  // namespace

std::vector<KittiBagFrame> selectKittiBagFrames(const std::string& drive_dir, int max_frames) {
  const fs::path drive(drive_dir);
  const std::vector<kitti::Frame> complete = kitti::listFrames(drive_dir);
  reportIncomplete(drive, complete);
  if (complete.empty()) {
    throw std::runtime_error("KITTI: " + drive_dir +
                             " has no frame with image_02, image_03 and velodyne_points data");
  }
  const DriveStampFiles stamps = readStampFiles(drive);
  std::vector<KittiBagFrame> frames;
  std::vector<std::string> unstamped;
  for (const auto& files : complete) {
    if (max_frames > 0 && static_cast<int>(frames.size()) >= max_frames) break;
    const size_t index = kitti::frameIndex(files.name);
    const auto image_stamp = stampOf(stamps.images, index);
    const auto sweep_stamp = stampOf(stamps.sweeps, index);
    if (!image_stamp || !sweep_stamp) {
      unstamped.push_back(files.name);
      continue;
    }
    KittiBagFrame frame;
    frame.files = files;
    frame.image_stamp = ros::Time(*image_stamp);
    frame.cloud_stamp = ros::Time(*sweep_stamp);
    frame.sweep = kitti::sweepClock(
        *sweep_stamp,
        stampOf(stamps.starts, index).value_or(std::numeric_limits<double>::quiet_NaN()),
        stamps.have_end);
    frames.push_back(frame);
  }
  if (!unstamped.empty()) {
    std::cerr << "kitti_to_bag: skipping " << unstamped.size()
              << " frame(s) with no line (or a blank line) in the image_02 or velodyne_points "
                 "timestamps: "
              << joined(unstamped) << "\n";
  }
  if (frames.empty())
    throw std::runtime_error("KITTI: no frame of " + drive_dir +
                             " has both an image and a Velodyne timestamp");
  return frames;
}

std::vector<KittiBagFrame> restampKittiBagFrames(const std::vector<KittiBagFrame>& frames,
                                                 double period, int cycles) {
  if (period <= 0.0) return frames;
  std::vector<KittiBagFrame> stream;
  const ros::Time first = frames.front().image_stamp;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    for (const KittiBagFrame& frame : frames) {
      const ros::Duration sweep_offset = frame.cloud_stamp - frame.image_stamp;
      KittiBagFrame next = frame;
      next.image_stamp = first + ros::Duration(period * static_cast<double>(stream.size()));
      next.cloud_stamp = next.image_stamp + sweep_offset;
      if (cycle == 0 && std::abs(sweep_offset.toSec()) >= 0.5 * period) {
        std::cerr << "kitti_to_bag: warning: frame " << frame.files.name << ": its sweep is "
                  << sweep_offset.toSec()
                  << " s from its images, half the --period or more: a consumer may pair it "
                     "with a neighbouring frame's images\n";
      }
      stream.push_back(next);
    }
  }
  return stream;
}

}  // namespace lidar_stereo_fusion
