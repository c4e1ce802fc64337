// Writes synthetic frames in the KITTI raw layout, so that every KITTI tool reads them:
//   <root>/<date>/calib_cam_to_cam.txt, calib_velo_to_cam.txt
//   <root>/<date>/<date>_drive_<NNNN>_sync/image_02/data/<frame>.png      (left, BGR8)
//                                          image_03/data/<frame>.png      (right)
//                                          velodyne_points/data/<frame>.bin (float32 x y z i)
//                                          {image_02,image_03,velodyne_points}/timestamps*.txt
//                                          proj_depth/groundtruth/image_02/<frame>.png
//   (KITTI depth-completion format: uint16, metres * 256, 0 = none; exact, dense except sky)
#pragma once

#include <string>

#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {
namespace sim {

struct KittiExportOptions {
  std::string date = "2000_01_01";  ///< the date folder, YYYY_MM_DD
  int drive = 1;                    ///< drive number, 0..9999
  int num_frames = 3;               ///< frames 0 .. num_frames - 1
};

/// Writes calib_cam_to_cam.txt and calib_velo_to_cam.txt into `date_dir` in KITTI's format. The
/// synthetic left camera is KITTI's rectified cam 2 and cam 0 at once: R_rect_00 = I,
/// P_rect_02 = P_rect_00 = K [I | 0], P_rect_03 = P_rect_01 = K [I | (-B, 0, 0)], and
/// [R | T]_velo_to_cam = T_cam_lidar. Throws std::runtime_error when a file cannot be written.
void writeKittiCalibration(const std::string& date_dir, const StereoCamera& camera,
                           const Eigen::Isometry3d& T_cam_lidar);

/// Writes images, sweep and ground-truth depth of `frame` as frame number `index` into
/// `drive_dir` (creating folders). Timestamps are written by writeKittiDrive.
void writeKittiFrame(const std::string& drive_dir, int index, const SyntheticFrame& frame);

/// Generates frames 0 .. num_frames - 1 of the street scene and writes them under `root`.
/// Returns the drive folder. Throws std::invalid_argument on bad options, std::runtime_error when
/// writing fails.
std::string writeKittiDrive(const std::string& root, const SyntheticParams& params,
                            const KittiExportOptions& options);

}  // namespace sim
}  // namespace lidar_stereo_fusion
