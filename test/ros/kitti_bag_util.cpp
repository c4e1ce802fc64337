#include "kitti_bag_util.h"

#include <filesystem>

#include <rosbag/view.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {
namespace test {

std::string scratchDir(const std::string& name) {
  const fs::path dir = fs::path(LSF_BINARY_DIR) / name;
  fs::create_directories(dir);
  return dir.string();
}

std::string makeSubsetDrive(const std::string& scratch, const std::vector<std::string>& frames) {
  const fs::path src_date = dataPath(kKittiDate);
  const fs::path src = src_date / kKittiDrive;
  const fs::path date = fs::path(scratch) / "subset" / "2011_09_26";
  const fs::path drive = date / kKittiDrive;
  fs::remove_all(date);
  for (const char* calib : {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt"}) {
    fs::create_directories(date);
    fs::create_symlink(src_date / calib, date / calib);
  }
  for (const std::string sensor : {"image_02", "image_03", "velodyne_points"}) {
    fs::create_directories(drive / sensor / "data");
    for (const auto& entry : fs::directory_iterator(src / sensor)) {
      if (entry.path().extension() == ".txt") {
        fs::create_symlink(entry.path(), drive / sensor / entry.path().filename());
      }
    }
    const std::string ext = sensor == "velodyne_points" ? ".bin" : ".png";
    for (const std::string& frame : frames) {
      fs::create_symlink(src / sensor / "data" / (frame + ext),
                         drive / sensor / "data" / (frame + ext));
    }
  }
  return drive.string();
}

std::map<std::string, std::vector<rosbag::MessageInstance>> readBag(const std::string& path,
                                                                    rosbag::Bag& bag) {
  bag.open(path, rosbag::bagmode::Read);
  std::map<std::string, std::vector<rosbag::MessageInstance>> by_topic;
  rosbag::View view(bag);
  for (const rosbag::MessageInstance& m : view) by_topic[m.getTopic()].push_back(m);
  return by_topic;
}

double kittiStamp(const std::string& file, const std::string& frame) {
  const std::vector<double> stamps = kitti::readTimestamps(file);
  const size_t index = std::stoul(frame);
  return index < stamps.size() ? stamps[index] : -1.0;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
