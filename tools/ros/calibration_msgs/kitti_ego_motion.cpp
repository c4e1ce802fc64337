// KITTI ego-motion as TF messages (oxts poses, IMU -> Velodyne).
#include "lidar_stereo_fusion/ros/kitti_ego_motion.h"

#include <filesystem>

#include "lidar_stereo_fusion/ros/calibration_msgs.h"

namespace lidar_stereo_fusion {

namespace fs = std::filesystem;

geometry_msgs::TransformStamped kittiImuToVelodyne(const Eigen::Isometry3d& T_velo_imu,
                                                   const std::string& imu_frame,
                                                   const std::string& velodyne_frame,
                                                   const ros::Time& stamp) {
  return transformMsg(T_velo_imu.inverse(), imu_frame, velodyne_frame, stamp);
}

std::vector<geometry_msgs::TransformStamped> kittiEgoMotionTf(
    const std::vector<kitti::OxtsSample>& samples, const std::string& fixed_frame,
    const std::string& imu_frame) {
  const std::vector<Eigen::Isometry3d> poses = kitti::posesRelativeToFirst(samples);
  std::vector<geometry_msgs::TransformStamped> transforms;
  for (size_t i = 0; i < poses.size(); ++i) {
    transforms.push_back(
        transformMsg(poses[i], fixed_frame, imu_frame, ros::Time(samples[i].stamp)));
  }
  return transforms;
}

std::vector<kitti::OxtsSample> samplesBracketing(const std::vector<kitti::OxtsSample>& all,
                                                 double first, double last) {
  std::vector<kitti::OxtsSample> kept;
  for (size_t i = 0; i < all.size(); ++i) {
    const bool after_first = i + 1 == all.size() || all[i + 1].stamp > first;
    const bool before_last = i == 0 || all[i - 1].stamp < last;
    if (after_first && before_last) kept.push_back(all[i]);
  }
  return kept;
}

KittiEgoMotion readKittiEgoMotion(const std::string& calib_dir, const std::string& drive_dir,
                                  bool restamped, double first, double last, std::ostream& notes) {
  KittiEgoMotion ego;
  const fs::path calib = fs::path(calib_dir) / "calib_imu_to_velo.txt";
  const fs::path oxts_data = fs::path(drive_dir) / "oxts" / "data";
  if (!fs::is_regular_file(calib)) {
    notes << "kitti_to_bag: no " << calib.string()
          << ": no IMU -> Velodyne transform and no ego-motion on /tf\n";
    return ego;
  }
  ego.T_velo_imu = kitti::readImuToVelo(calib_dir);
  if (restamped) {
    notes << "kitti_to_bag: --period: no ego-motion on /tf (the frames are restamped, the oxts "
             "packets are not)\n";
  } else if (!fs::is_directory(oxts_data)) {
    notes << "kitti_to_bag: no " << oxts_data.string() << ": no ego-motion on /tf\n";
  } else {
    std::vector<std::string> unstamped;
    ego.samples = samplesBracketing(kitti::readOxtsDrive(drive_dir, &unstamped), first, last);
    if (!unstamped.empty()) {
      notes << "kitti_to_bag: skipping " << unstamped.size()
            << " oxts packet(s) with no line (or a blank line) in oxts/timestamps.txt:";
      for (const std::string& name : unstamped) notes << " " << name;
      notes << "\n";
    }
  }
  return ego;
}

}  // namespace lidar_stereo_fusion
