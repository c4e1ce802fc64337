// kitti_to_bag: converts a KITTI raw drive (synced + rectified) into a ROS 1 bag with the topics
// of the stereo + LiDAR rig, so that the fusion nodelet can be replayed on real data.
//
//   kitti_to_bag --kitti-raw <date>/<drive>_sync --out <file.bag> [--frames N]
//                [--calib-dir <date>] [--compression none|lz4|bz2] [--period S [--cycles N]]
//
// Topics (message time = header stamp):
//   /stereo/left/image_rect_color    sensor_msgs/Image bgr8, frame left_camera_optical_frame
//   /stereo/left/camera_info         rectified: D = 0, R = I, P = [K | 0]
//   /stereo/right/image_rect_color   sensor_msgs/Image bgr8, frame right_camera_optical_frame
//   /stereo/right/camera_info        P = [K | (-fx * B, 0, 0)^T]
//   /velodyne_points                 sensor_msgs/PointCloud2, frame velodyne: x, y, z, intensity
//                                    float32 [m, m, m, reflectance], ring uint16, time float32 [s]
//   /tf_static                       velodyne -> left_camera_optical_frame (T_cam_velo^-1) and
//                                    left -> right optical frame (+B along x); latched on replay;
//                                    with calib_imu_to_velo.txt also imu_link -> velodyne
//   /tf                              odom -> imu_link at the oxts/timestamps.txt stamps of the
//                                    oxts/data packets bracketing the frames: the ego-motion (the
//                                    devkit's Mercator poses relative to the first of them); not
//                                    with --period, whose stamps are not the drive's
//
// Stamps come from the KITTI timestamp files. Both images of a pair (and both camera infos) take
// the image_02 stamp: the pair is hardware-triggered and rectified together, the image_03 stamps
// differ by < 1 ms, and a stereo consumer needs one stamp per pair. The cloud is stamped at the
// end of its sweep (velodyne_points/timestamps_end.txt), as velodyne_driver stamps a scan at its
// last packet: about 40 ms after the images here (near, not equal). Without timestamps_end.txt
// it takes timestamps.txt, the instant the scanner faced forward and triggered the cameras.
// Per-point `time` is the offset [s] from the cloud stamp, from the point's azimuth
// (kitti::azimuthTime: the sweep runs clockwise from the rear at timestamps_start.txt through the
// front to the rear at timestamps_end.txt), in [-(end - start), 0].
// Rings are recovered from the sweep storage order (recoverRingsBySweepOrder).
//
// --period S restamps the frames as a stream at a fixed period: frame k's images at the first
// image stamp + k S, each sweep at its own offset from its images. --cycles N writes that stream N
// times in a row, stamps going on. For rate and latency tests at the sensor's rate on a drive that
// keeps only some frames (the shared KITTI sample keeps every 5th: 0.5 s apart).
//
// Only frames with image_02, image_03, a Velodyne sweep and non-blank image and Velodyne stamps
// are written (KITTI leaves blank lines for dropped sweeps); the others are listed as skipped.
// Exit status: 0 written, 1 bad input or write failure, 2 bad command line.
// The frames and their stamps (and --period restamping): kitti_to_bag/kitti_bag_frames.cpp.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <ros/message_traits.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <boost/make_shared.hpp>

#include "kitti_to_bag/kitti_bag_frames.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_sweep.h"
#include "lidar_stereo_fusion/ros/calibration_msgs.h"
#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/kitti_ego_motion.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

constexpr char kLeftFrame[] = "left_camera_optical_frame";
constexpr char kRightFrame[] = "right_camera_optical_frame";
constexpr char kVelodyneFrame[] = "velodyne";
constexpr char kLeftImageTopic[] = "/stereo/left/image_rect_color";
constexpr char kLeftInfoTopic[] = "/stereo/left/camera_info";
constexpr char kRightImageTopic[] = "/stereo/right/image_rect_color";
constexpr char kRightInfoTopic[] = "/stereo/right/camera_info";
constexpr char kCloudTopic[] = "/velodyne_points";
constexpr char kTfStaticTopic[] = "/tf_static";
constexpr char kTfTopic[] = "/tf";
constexpr char kImuFrame[] = "imu_link";
constexpr char kFixedFrame[] = "odom";
constexpr size_t kHdl64Rings = 64;

struct Options {
  std::string drive_dir;
  std::string out;
  std::string calib_dir;  ///< empty = parent of drive_dir
  int max_frames = -1;    ///< -1 = all
  double period = 0.0;    ///< [s] > 0: restamp the frames at this period
  int cycles = 1;         ///< times the (restamped) frames are written
  rosbag::CompressionType compression = rosbag::compression::Uncompressed;
};

const char* usage() {
  return "usage: kitti_to_bag --kitti-raw <date>/<drive>_sync --out <file.bag> [--frames N]\n"
         "                    [--calib-dir <date folder>] [--compression none|lz4|bz2]\n"
         "                    [--period S [--cycles N]]\n"
         "  Writes the frames that have image_02, image_03 and a Velodyne sweep (the first N with\n"
         "  --frames) as /stereo/{left,right}/{image_rect_color,camera_info}, /velodyne_points\n"
         "  and /tf_static. --calib-dir defaults to the drive folder's parent.\n"
         "  --period S stamps frame k's images at the first image stamp + k S (each sweep keeps\n"
         "  its offset from its images), and --cycles N writes these frames N times in a row:\n"
         "  a stream at the sensor's rate from a drive that keeps only some frames.\n";
}

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv,
      {"--kitti-raw", "--out", "--calib-dir", "--frames", "--compression", "--period", "--cycles"},
      {});
  Options options;
  options.drive_dir = cl.value("--kitti-raw");
  options.out = cl.value("--out");
  options.calib_dir = cl.value("--calib-dir");
  options.max_frames = cl.intValue("--frames", -1, 1, 1000000);
  options.period = cl.doubleValue("--period", 0.0, 0.001, 10.0);  // 0: not restamped
  options.cycles = cl.intValue("--cycles", 1, 1, 1000000);
  const std::string compression = cl.choice("--compression", "none", {"none", "lz4", "bz2"});
  options.compression = compression == "lz4"   ? rosbag::compression::LZ4
                        : compression == "bz2" ? rosbag::compression::BZ2
                                               : rosbag::compression::Uncompressed;
  if (options.drive_dir.empty()) throw lsf::UsageError("--kitti-raw is required");
  if (options.out.empty()) throw lsf::UsageError("--out is required");
  if (options.cycles > 1 && options.period <= 0.0) {
    throw lsf::UsageError("--cycles needs --period (the stamps of a repeated frame must go on)");
  }
  if (options.calib_dir.empty())
    options.calib_dir = lsf::kitti::calibrationDirOf(options.drive_dir);
  return options;
}

/// Reads a frame (images checked against the calibration's size, rings recovered by sweep order).
lsf::kitti::FrameData loadFrame(const lsf::KittiBagFrame& frame, const lsf::StereoCamera& camera) {
  lsf::kitti::FrameData data = lsf::kitti::loadFrame(frame.files, camera);
  if (data.cloud.empty()) {
    throw std::runtime_error("KITTI: Velodyne sweep " + frame.files.velodyne + " is empty");
  }
  std::set<int> rings;
  for (const lsf::LidarPoint& p : data.cloud) rings.insert(p.ring);
  if (rings.size() != kHdl64Rings) {
    std::cerr << "kitti_to_bag: warning: frame " << frame.files.name << ": recovered "
              << rings.size() << " rings, an HDL-64E sweep has " << kHdl64Rings << "\n";
  }
  lsf::kitti::setPointTimesFromAzimuth(data.cloud, frame.sweep);
  return data;
}

/// Connection header that makes `rosbag play` re-advertise the topic latched (as tf2 publishes
/// /tf_static), so that late subscribers still get the static transforms.
template <typename Msg>
boost::shared_ptr<ros::M_string> latchedConnectionHeader() {
  auto header = boost::make_shared<ros::M_string>();
  (*header)["callerid"] = "/kitti_to_bag";
  (*header)["latching"] = "1";
  (*header)["type"] = ros::message_traits::datatype<Msg>();
  (*header)["md5sum"] = ros::message_traits::md5sum<Msg>();
  (*header)["message_definition"] = ros::message_traits::definition<Msg>();
  return header;
}

std::string partialPath(const Options& options) { return options.out + ".partial"; }

/// The static transforms (velodyne -> left, left -> right, imu -> velodyne) at the bag's
/// earliest stamp (their stamps do not matter to tf2's static buffer; a first message time keeps
/// `rosbag play` from waiting), then the ego-motion on /tf.
void writeTransforms(rosbag::Bag& bag, const lsf::kitti::Calibration& calib,
                     const std::vector<lsf::KittiBagFrame>& frames,
                     const lsf::KittiEgoMotion& ego) {
  ros::Time first = frames.front().image_stamp;
  for (const auto& f : frames) first = std::min({first, f.image_stamp, f.cloud_stamp});
  if (!ego.samples.empty()) first = std::min(first, ros::Time(ego.samples.front().stamp));
  tf2_msgs::TFMessage tf_static;
  tf_static.transforms.push_back(
      lsf::kittiVelodyneToCamera(calib, kVelodyneFrame, kLeftFrame, first));
  tf_static.transforms.push_back(
      lsf::stereoLeftToRight(calib.camera, kLeftFrame, kRightFrame, first));
  if (ego.T_velo_imu) {
    tf_static.transforms.push_back(
        lsf::kittiImuToVelodyne(*ego.T_velo_imu, kImuFrame, kVelodyneFrame, first));
  }
  bag.write(kTfStaticTopic, first, tf_static, latchedConnectionHeader<tf2_msgs::TFMessage>());
  for (const auto& transform : lsf::kittiEgoMotionTf(ego.samples, kFixedFrame, kImuFrame)) {
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(transform);
    bag.write(kTfTopic, transform.header.stamp, tf);
  }
}

/// One frame's sweep, camera infos and images (`seq` numbers its headers).
void writeFrame(rosbag::Bag& bag, const lsf::KittiBagFrame& frame, uint32_t seq,
                const lsf::kitti::Calibration& calib) {
  std_msgs::Header left_header, right_header, cloud_header;
  left_header.seq = right_header.seq = cloud_header.seq = seq;
  left_header.stamp = right_header.stamp = frame.image_stamp;
  left_header.frame_id = kLeftFrame;
  right_header.frame_id = kRightFrame;
  cloud_header.stamp = frame.cloud_stamp;
  cloud_header.frame_id = kVelodyneFrame;

  sensor_msgs::CameraInfo left_info = lsf::rectifiedCameraInfo(calib.camera, kLeftFrame, false);
  sensor_msgs::CameraInfo right_info = lsf::rectifiedCameraInfo(calib.camera, kRightFrame, true);
  left_info.header = left_header;
  right_info.header = right_header;
  const lsf::kitti::FrameData data = loadFrame(frame, calib.camera);
  // The fields of velodyne_pointcloud: x, y, z, intensity, ring, time.
  sensor_msgs::PointCloud2 cloud = lsf::conversions::cloudToMsg(data.cloud, cloud_header);
  cloud.is_dense = std::all_of(data.cloud.begin(), data.cloud.end(), [](const lsf::LidarPoint& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  });
  bag.write(kCloudTopic, frame.cloud_stamp, cloud);
  bag.write(kLeftInfoTopic, frame.image_stamp, left_info);
  bag.write(kLeftImageTopic, frame.image_stamp,
            cv_bridge::CvImage(left_header, "bgr8", data.left).toImageMsg());
  bag.write(kRightInfoTopic, frame.image_stamp, right_info);
  bag.write(kRightImageTopic, frame.image_stamp,
            cv_bridge::CvImage(right_header, "bgr8", data.right).toImageMsg());
  std::cout << "kitti_to_bag: frame " << frame.files.name << ": images at " << frame.image_stamp
            << " s, " << cloud.width << " points at " << frame.cloud_stamp << " s\n";
}

void writeBag(const Options& options, const lsf::kitti::Calibration& calib,
              const std::vector<lsf::KittiBagFrame>& frames, const lsf::KittiEgoMotion& ego) {
  // Written under a temporary name and renamed when complete, so that a failed conversion never
  // leaves a truncated bag under the requested name.
  rosbag::Bag bag;
  bag.open(partialPath(options), rosbag::bagmode::Write);
  bag.setCompression(options.compression);
  writeTransforms(bag, calib, frames, ego);
  uint32_t seq = 0;
  for (const lsf::KittiBagFrame& frame : frames) writeFrame(bag, frame, seq++, calib);
  bag.close();
  fs::rename(partialPath(options), options.out);
}

/// The drive's ego-motion for the frames' time span (oxts packets not with --period).
lsf::KittiEgoMotion readEgoMotion(const Options& options,
                                  const std::vector<lsf::KittiBagFrame>& frames) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const lsf::KittiBagFrame& f : frames) {
    lo = std::min({lo, f.image_stamp.toSec(), f.cloud_stamp.toSec() - f.sweep.stamp_after_start});
    hi = std::max({hi, f.image_stamp.toSec(), f.cloud_stamp.toSec()});
  }
  return lsf::readKittiEgoMotion(options.calib_dir, options.drive_dir, options.period > 0.0, lo, hi,
                                 std::cerr);
}

void removePartial(const Options& options) {
  std::error_code ignored;
  fs::remove(partialPath(options), ignored);
}

/// Writes the bag; on any failure removes the partial file first.
int run(const Options& options) {
  try {
    if (!fs::is_directory(options.drive_dir)) {
      throw std::runtime_error("KITTI: --kitti-raw " + options.drive_dir + " is not a folder");
    }
    const lsf::kitti::Calibration calib = lsf::kitti::readCalibration(options.calib_dir);
    const std::vector<lsf::KittiBagFrame> frames =
        lsf::restampKittiBagFrames(lsf::selectKittiBagFrames(options.drive_dir, options.max_frames),
                                   options.period, options.cycles);
    writeBag(options, calib, frames, readEgoMotion(options, frames));
    std::cout << "kitti_to_bag: wrote " << frames.size() << " frame(s) to " << options.out << "\n";
  } catch (const rosbag::BagException& e) {
    removePartial(options);
    throw std::runtime_error("cannot write bag " + options.out + ": " + e.what());
  } catch (...) {
    removePartial(options);
    throw;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("kitti_to_bag", usage(), argc, argv,
                       [&] { return run(parseOptions(argc, argv)); });
}
