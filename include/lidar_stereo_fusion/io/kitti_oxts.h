// KITTI raw ego-motion: the OXTS (GPS/IMU) packets of a drive (oxts/data/*.txt,
// oxts/timestamps.txt), the IMU -> Velodyne calibration (calib_imu_to_velo.txt), the rig's
// velocity in any of its frames, and the devkit's poses (convertOxtsToPose). ROS-free.
//
// Frames: the IMU (vehicle) frame has x forward, y left, z up. The OXTS "level" frame is the
// vehicle frame turned by roll and pitch back to the earth's surface (heading kept): x forward
// parallel to the surface, z up perpendicular to it. vf, vl, vu and wf, wl, wu are in the level
// frame; ax, ay, az and wx, wy, wz in the vehicle frame (oxts/dataformat.txt).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace lidar_stereo_fusion {
namespace kitti {

/// One OXTS packet: the 30 values of an oxts/data/<frame>.txt line, in oxts/dataformat.txt order.
struct OxtsPacket {
  double lat = 0, lon = 0;  ///< latitude, longitude [deg]
  double alt = 0;           ///< altitude [m]
  /// [rad] roll: 0 = level, positive = left side up; pitch: positive = front down; yaw
  /// (heading): 0 = east, positive = counter-clockwise.
  double roll = 0, pitch = 0, yaw = 0;
  double vn = 0, ve = 0;          ///< velocity towards north, east [m/s]
  double vf = 0, vl = 0, vu = 0;  ///< forward, leftward, upward velocity, level frame [m/s]
  double ax = 0, ay = 0, az = 0;  ///< acceleration, vehicle frame [m/s^2]
  double af = 0, al = 0, au = 0;  ///< acceleration, level frame [m/s^2]
  double wx = 0, wy = 0, wz = 0;  ///< angular rate, vehicle frame [rad/s]
  double wf = 0, wl = 0, wu = 0;  ///< angular rate, level frame [rad/s]
  double pos_accuracy = 0;        ///< [m]
  double vel_accuracy = 0;        ///< [m/s]
  int navstat = 0, numsats = 0, posmode = 0, velmode = 0, orimode = 0;  ///< receiver status
};

/// Reads one packet file: one line of exactly 30 numbers (25 finite reals, then 5 integers),
/// separated by blanks; blank lines after it are allowed. Throws std::runtime_error naming the
/// file, the line and the value (by its dataformat.txt name) when the file is missing or
/// unreadable, has no packet, another count of values, a value that is not a finite number (or not
/// an integer for the status fields), or a second packet line.
OxtsPacket readOxtsPacket(const std::string& path);

/// calib_imu_to_velo.txt in `dir` (keys R, T): T_velo_imu, which maps IMU coordinates into
/// Velodyne coordinates [m]. Throws std::runtime_error naming the file and key when the file or a
/// key is missing, a value is not a number, or R is not a rotation.
Eigen::Isometry3d readImuToVelo(const std::string& dir);

/// A rigid body's instantaneous velocity: its frame origin's linear velocity [m/s] and its angular
/// velocity [rad/s], both expressed in that frame.
struct Twist {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   ///< [m/s]
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  ///< [rad/s]
};

/// Rotation from the vehicle frame to the level frame: Ry(pitch) * Rx(roll) (the devkit's R =
/// Rz(yaw) Ry(pitch) Rx(roll) without the heading).
Eigen::Matrix3d levelFromVehicle(const OxtsPacket& packet);

/// The IMU's twist in the IMU (vehicle) frame: (vf, vl, vu) and (wf, wl, wu) turned from the level
/// frame into the vehicle frame by levelFromVehicle^T. On a level road this is (vf, vl, vu),
/// (wf, wl, wu) as they are; with 4 deg of roll it moves vl into vu by 7 %.
Twist imuTwist(const OxtsPacket& packet);

/// The twist of a frame B rigidly attached to frame A, T_b_a mapping A coordinates into B
/// coordinates: w_B = R w_A and v_B = R (v_A + w_A x p), with R = T_b_a's rotation and p = B's
/// origin in A (= -R^T t). E.g. the Velodyne's twist from the IMU's with T_velo_imu.
Twist transformTwist(const Twist& twist_a, const Eigen::Isometry3d& T_b_a);

/// The devkit's Mercator scale for a drive: cos(lat0) of its first packet's latitude [deg].
double mercatorScale(double lat0_deg);

/// Pose of the IMU in the devkit's Mercator frame (x east, y north, z up [m]; convertOxtsToPose):
/// translation (scale * lon * pi * r / 180, scale * r * log(tan((90 + lat) * pi / 360)), alt),
/// r = 6378137 m, rotation Rz(yaw) Ry(pitch) Rx(roll). Maps IMU coordinates into that frame.
Eigen::Isometry3d mercatorPose(const OxtsPacket& packet, double scale);

/// One packet of a drive with its stamp.
struct OxtsSample {
  std::string name;  ///< frame, e.g. "0000000016"
  double stamp = 0;  ///< [s] since the epoch, from oxts/timestamps.txt
  OxtsPacket packet;
};

/// Every oxts/data/*.txt of `drive_dir`, sorted by name, with its line of oxts/timestamps.txt
/// (line = frame number + 1). Packets without a stamp (a blank or missing line) are left out and
/// each named in `unstamped` when given. Throws std::runtime_error when oxts/data or
/// oxts/timestamps.txt is missing, a packet or a stamp is malformed, or a file name is not a frame
/// number.
std::vector<OxtsSample> readOxtsDrive(const std::string& drive_dir,
                                      std::vector<std::string>* unstamped = nullptr);

/// The IMU poses of `samples` relative to the first one's (T_first_i, the devkit's
/// convertOxtsToPose: mercatorPose with the first packet's mercatorScale, premultiplied by the
/// inverse of the first pose). Empty for no sample.
std::vector<Eigen::Isometry3d> posesRelativeToFirst(const std::vector<OxtsSample>& samples);

/// The frame number of a KITTI file stem ("0000000016" -> 16). Throws std::runtime_error naming
/// it when it is not a number.
size_t frameIndex(const std::string& name);

}  // namespace kitti
}  // namespace lidar_stereo_fusion
