// Reading and writing the KITTI raw layout and the KITTI depth-completion PNG format. ROS-free.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace kitti {

/// Calibration of one KITTI raw drive date (calib_cam_to_cam.txt + calib_velo_to_cam.txt).
///
/// Conventions: P_rect_0i = K [I | t_i] projects points of the rectified cam-0 frame into image i,
/// with t_i = K^-1 P_rect_0i[:, 3] the position of the rectified cam-0 origin in camera i's frame
/// (t_i.x = -b_i, b_i the x offset of camera i from camera 0; P_rect_0i[0, 3] = -fx b_i when the
/// other entries of the last column are 0). The left camera here is rectified cam 2, so
///   T_cam_velo = Translation(t_2) * R_rect_00 * [R | T]_velo_to_cam,
/// and K * (T_cam_velo * X) equals P_rect_02 * R_rect_00 * [R | T] * X exactly (the KITTI devkit's
/// projection; its depth z is the same too). Baseline B = (P_rect_02[0, 3] - P_rect_03[0, 3]) / fx
/// (> 0: cam 3 is to the right of cam 2, 0.532 m on 2011_09_26).
struct Calibration {
  StereoCamera camera;                 ///< rectified cam 2 (left colour) with baseline to cam 3
  Eigen::Isometry3d T_cam_velo;        ///< Velodyne -> rectified cam 2 optical frame
  Eigen::Matrix<double, 3, 4> P2, P3;  ///< P_rect_02, P_rect_03
};

/// Reads `dir`/calib_cam_to_cam.txt and `dir`/calib_velo_to_cam.txt. Throws std::runtime_error
/// naming the file and the missing/malformed key.
Calibration readCalibration(const std::string& dir);

/// Reads a .bin sweep (float32 x, y, z, reflectance). Throws std::runtime_error when the file is
/// unreadable or its size is not a multiple of 16 bytes. Rings are left at -1.
LidarCloud readVelodyneBin(const std::string& path);
/// Writes a cloud as a .bin sweep.
void writeVelodyneBin(const std::string& path, const LidarCloud& cloud);

/// Reads a KITTI depth PNG (uint16, metres * 256, 0 = none) into metres. Throws on failure.
cv::Mat1f readDepthPng(const std::string& path);
/// Writes depth [m] (0 / NaN / inf = none) as a KITTI depth PNG. Throws on failure.
void writeDepthPng(const std::string& path, const cv::Mat1f& depth_m);

/// One frame of a drive (paths; files are read on demand).
struct Frame {
  std::string name;  ///< e.g. "0000000005"
  std::string left_image, right_image, velodyne;
};
/// Lists frames of `drive_dir` that have image_02, image_03 and a velodyne .bin, sorted by name.
/// Frames with an image_02 but without image_03 or the .bin are left out; when `incomplete` is
/// given, each gets a line there naming the frame and the missing file (sorted).
std::vector<Frame> listFrames(const std::string& drive_dir,
                              std::vector<std::string>* incomplete = nullptr);

/// Images and sweep of one frame, checked: both images readable, BGR8, of the calibration's size.
struct FrameData {
  cv::Mat left, right;  ///< BGR CV_8UC3 rectified image_02 / image_03
  LidarCloud cloud;     ///< the sweep, rings recovered by sweep order (0..63 on the HDL-64E)
  /// How the rings were recovered: sweep order when plausible (every KITTI .bin), else the beam
  /// model (a shuffled sweep), else elevation; `rings.plausible` false when none looks like a scan
  /// pattern.
  RingRecovery rings;
};
/// Reads a frame. 8-bit images are used as they are; 16-bit PNGs are scaled to 8 bits (value *
/// 255 / 65535), grey or BGRA to BGR. Throws std::runtime_error naming the file when an image is
/// unreadable or of another depth, the two images differ in size, or their size differs from
/// `camera`'s (when camera.width > 0).
FrameData loadFrame(const Frame& frame, const StereoCamera& camera);

/// The folder holding a drive's calibration files: the parent of `drive_dir`
/// (".../2011_09_26" for ".../2011_09_26/2011_09_26_drive_0009_sync").
std::string calibrationDirOf(const std::string& drive_dir);

/// Reads timestamps.txt lines ("2011-09-26 13:02:25.964389445") as seconds since the epoch (UTC),
/// one entry per line so that entry i belongs to frame i; an empty line (a dropped sample, as in
/// drive 0009's Velodyne timestamps) gives NaN. Throws std::runtime_error naming the file and line
/// of a malformed timestamp. (A double resolves ~0.2 us at 2011 epochs.)
std::vector<double> readTimestamps(const std::string& path);

}  // namespace kitti
}  // namespace lidar_stereo_fusion
