// The frames of a KITTI raw drive that kitti_to_bag writes, with their stamps: the complete frames
// (image_02, image_03 and a Velodyne sweep) with an image and a sweep stamp, and the same frames
// restamped as a stream at a fixed period (--period, --cycles).
#pragma once

#include <string>
#include <vector>

#include <ros/time.h>

#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_sweep.h"

namespace lidar_stereo_fusion {

/// One frame to write, with its stamps.
struct KittiBagFrame {
  kitti::Frame files;
  ros::Time image_stamp;    ///< both images and camera_infos: image_02/timestamps.txt
  ros::Time cloud_stamp;    ///< the sweep: its end (timestamps_end.txt), else timestamps.txt
  kitti::SweepClock sweep;  ///< its period and stamp_after_start give the point times
};

/// Chooses the frames of `drive_dir` to write (the first `max_frames`, all when <= 0) and their
/// stamps; prints to std::cerr which frames are skipped and why (not complete, no stamp, sweeps
/// stamped mid-sweep without timestamps_end.txt). Throws std::runtime_error when no frame is left.
std::vector<KittiBagFrame> selectKittiBagFrames(const std::string& drive_dir, int max_frames);

/// --period / --cycles: the frames as a stream, frame k's images at the first image stamp +
/// k `period` [s], each sweep at its own offset from its images, `cycles` times in a row (stamps
/// going on); warns about a sweep half a period or more from its images. `period` <= 0: the
/// frames as they are.
std::vector<KittiBagFrame> restampKittiBagFrames(const std::vector<KittiBagFrame>& frames,
                                                 double period, int cycles);

}  // namespace lidar_stereo_fusion
