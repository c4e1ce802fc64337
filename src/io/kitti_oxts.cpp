// KITTI raw OXTS packets, calib_imu_to_velo.txt, twists and the devkit's Mercator poses.
#include "lidar_stereo_fusion/io/kitti_oxts.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "kitti_key_value.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace kitti {
namespace {

namespace fs = std::filesystem;

constexpr size_t kOxtsValues = 30;
constexpr size_t kOxtsReals = 25;           ///< then 5 integer status fields
constexpr double kEarthRadius = 6378137.0;  ///< [m] the devkit's er

/// The names of oxts/dataformat.txt, in order (its third acceleration is misnamed "ay" there).
constexpr std::array<const char*, kOxtsValues> kOxtsNames = {
    "lat",          "lon",     "alt",     "roll",    "pitch",   "yaw",    "vn", "ve",
    "vf",           "vl",      "vu",      "ax",      "ay",      "az",     "af", "al",
    "au",           "wx",      "wy",      "wz",      "wf",      "wl",     "wu", "pos_accuracy",
    "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"};

bool isBlank(const std::string& line) {
  return line.find_first_not_of(" \t\r") == std::string::npos;
}

/// The packet's fields in file order, for filling from 30 numbers.
std::array<double*, kOxtsReals> realFields(OxtsPacket& p) {
  return {&p.lat, &p.lon, &p.alt, &p.roll, &p.pitch, &p.yaw,          &p.vn,          &p.ve, &p.vf,
          &p.vl,  &p.vu,  &p.ax,  &p.ay,   &p.az,    &p.af,           &p.al,          &p.au, &p.wx,
          &p.wy,  &p.wz,  &p.wf,  &p.wl,   &p.wu,    &p.pos_accuracy, &p.vel_accuracy};
}

std::array<int*, kOxtsValues - kOxtsReals> statusFields(OxtsPacket& p) {
  return {&p.navstat, &p.numsats, &p.posmode, &p.velmode, &p.orimode};
}

/// Parses the 30 values of one packet line; throws naming file, line and value.
OxtsPacket parsePacketLine(const std::string& line, const std::string& where) {
  std::istringstream in(line);
  std::vector<std::string> tokens;
  for (std::string token; in >> token;) tokens.push_back(token);
  if (tokens.size() != kOxtsValues) {
    throw std::runtime_error("KITTI oxts: " + where + " has " + std::to_string(tokens.size()) +
                             " values, expected " + std::to_string(kOxtsValues) +
                             " (oxts/dataformat.txt)");
  }
  OxtsPacket packet;
  const auto reals = realFields(packet);
  const auto status = statusFields(packet);
  for (size_t i = 0; i < kOxtsValues; ++i) {
    const char* text = tokens[i].c_str();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(text, &end);
    const bool number = end != text && *end == '\0' && errno != ERANGE && std::isfinite(value);
    const bool integer = number && value == std::floor(value) && std::abs(value) < 1e9;
    if (!number || (i >= kOxtsReals && !integer)) {
      throw std::runtime_error("KITTI oxts: " + where + " value " + std::to_string(i + 1) + " (" +
                               kOxtsNames[i] + ") is not " +
                               (i >= kOxtsReals ? "an integer" : "a finite number") + ": '" +
                               tokens[i] + "'");
    }
    if (i < kOxtsReals) {
      *reals[i] = value;
    } else {
      *status[i - kOxtsReals] = static_cast<int>(value);
    }
  }
  return packet;
}

Eigen::Matrix3d rotationX(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d rotationY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d rotationZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

OxtsPacket readOxtsPacket(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("KITTI oxts: cannot open packet " + path);
  std::string line;
  int number = 0, packet_line = 0;
  OxtsPacket packet;
  while (std::getline(in, line)) {
    ++number;
    if (isBlank(line)) continue;
    if (packet_line > 0) {
      throw std::runtime_error("KITTI oxts: " + path + " line " + std::to_string(number) +
                               ": a second packet (line " + std::to_string(packet_line) +
                               " is one); a packet file holds one line");
    }
    packet = parsePacketLine(line, path + " line " + std::to_string(number));
    packet_line = number;
  }
  if (in.bad()) throw std::runtime_error("KITTI oxts: cannot read packet " + path);
  if (packet_line == 0) throw std::runtime_error("KITTI oxts: " + path + " has no packet line");
  return packet;
}

Eigen::Isometry3d readImuToVelo(const std::string& dir) {
  const fs::path path = fs::path(dir) / "calib_imu_to_velo.txt";
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error("KITTI: missing calibration file " + path.string());
  }
  const detail::KeyValueFile file(path.string());
  const Eigen::Matrix3d r = detail::readMatrix<3, 3>(file, "R");
  detail::requireRotation(r, file.path(), "R");
  Eigen::Isometry3d T_velo_imu = Eigen::Isometry3d::Identity();
  // Re-orthonormalised: the file's 7 digits leave R 1e-7 off a rotation, and the transform is
  // chained and inverted (TF, ego-motion).
  T_velo_imu.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  T_velo_imu.translation() = detail::readMatrix<3, 1>(file, "T");
  return T_velo_imu;
}

Eigen::Matrix3d levelFromVehicle(const OxtsPacket& packet) {
  return rotationY(packet.pitch) * rotationX(packet.roll);
}

Twist imuTwist(const OxtsPacket& packet) {
  const Eigen::Matrix3d vehicle_from_level = levelFromVehicle(packet).transpose();
  Twist twist;
  twist.linear = vehicle_from_level * Eigen::Vector3d(packet.vf, packet.vl, packet.vu);
  twist.angular = vehicle_from_level * Eigen::Vector3d(packet.wf, packet.wl, packet.wu);
  return twist;
}

Twist transformTwist(const Twist& twist_a, const Eigen::Isometry3d& T_b_a) {
  const Eigen::Matrix3d R = T_b_a.linear();
  const Eigen::Vector3d b_origin_in_a = -R.transpose() * T_b_a.translation();
  Twist twist_b;
  twist_b.angular = R * twist_a.angular;
  twist_b.linear = R * (twist_a.linear + twist_a.angular.cross(b_origin_in_a));
  return twist_b;
}

double mercatorScale(double lat0_deg) { return std::cos(lat0_deg * M_PI / 180.0); }

Eigen::Isometry3d mercatorPose(const OxtsPacket& packet, double scale) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(
      scale * packet.lon * M_PI * kEarthRadius / 180.0,
      scale * kEarthRadius * std::log(std::tan((90.0 + packet.lat) * M_PI / 360.0)), packet.alt);
  pose.linear() = rotationZ(packet.yaw) * rotationY(packet.pitch) * rotationX(packet.roll);
  return pose;
}

std::vector<Eigen::Isometry3d> posesRelativeToFirst(const std::vector<OxtsSample>& samples) {
  std::vector<Eigen::Isometry3d> poses;
  if (samples.empty()) return poses;
  const double scale = mercatorScale(samples.front().packet.lat);
  const Eigen::Isometry3d first_inverse = mercatorPose(samples.front().packet, scale).inverse();
  for (const OxtsSample& sample : samples) {
    poses.push_back(first_inverse * mercatorPose(sample.packet, scale));
  }
  return poses;
}

size_t frameIndex(const std::string& name) {
  size_t used = 0, index = 0;
  try {
    index = std::stoul(name, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != name.size() || name.front() == '-' || name.front() == '+') {
    throw std::runtime_error("KITTI: frame file name " + name +
                             " is not a frame number (expected e.g. 0000000005)");
  }
  return index;
}

std::vector<OxtsSample> readOxtsDrive(const std::string& drive_dir,
                                      std::vector<std::string>* unstamped) {
  const fs::path oxts = fs::path(drive_dir) / "oxts";
  if (!fs::is_directory(oxts / "data")) {
    throw std::runtime_error("KITTI oxts: missing folder " + (oxts / "data").string());
  }
  if (!fs::is_regular_file(oxts / "timestamps.txt")) {
    throw std::runtime_error("KITTI oxts: missing " + (oxts / "timestamps.txt").string());
  }
  const std::vector<double> stamps = readTimestamps((oxts / "timestamps.txt").string());
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(oxts / "data")) {
    if (entry.is_regular_file() && entry.path().extension() == ".txt") files.push_back(entry);
  }
  std::sort(files.begin(), files.end());
  std::vector<OxtsSample> samples;
  for (const fs::path& file : files) {
    const std::string name = file.stem().string();
    const size_t index = frameIndex(name);
    if (index >= stamps.size() || !std::isfinite(stamps[index])) {
      if (unstamped) unstamped->push_back(name);
      continue;
    }
    samples.push_back({name, stamps[index], readOxtsPacket(file.string())});
  }
  return samples;
}

}  // namespace kitti
}  // namespace lidar_stereo_fusion
