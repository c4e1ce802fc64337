// Synthetic frames -> KITTI raw layout (calibration text files, PNGs, .bin sweeps, timestamps).
#include "lidar_stereo_fusion/sim/kitti_export.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

namespace fs = std::filesystem;

/// "%e"-formatted numbers separated by spaces, as in KITTI's calibration files.
std::string numbers(std::initializer_list<double> values) {
  std::string out;
  char buffer[32];
  for (double v : values) {
    std::snprintf(buffer, sizeof(buffer), "%e", v);
    if (!out.empty()) out += ' ';
    out += buffer;
  }
  return out;
}

std::string matrixRowMajor(const Eigen::MatrixXd& m) {
  std::string out;
  char buffer[32];
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) {
      std::snprintf(buffer, sizeof(buffer), "%e", m(r, c));
      if (!out.empty()) out += ' ';
      out += buffer;
    }
  }
  return out;
}

std::ofstream openForWriting(const fs::path& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("KITTI export: cannot create " + path.string());
  out.precision(12);
  return out;
}

void closeChecked(std::ofstream& out, const fs::path& path) {
  out.close();
  if (!out) throw std::runtime_error("KITTI export: cannot write " + path.string());
}

void createDirectories(const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) {
    throw std::runtime_error("KITTI export: cannot create folder " + dir.string() + ": " +
                             error.message());
  }
}

void writePng(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) {
    throw std::runtime_error("KITTI export: cannot write " + path.string());
  }
}

std::string frameName(int index) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "%010d", index);
  return buffer;
}

/// "YYYY-MM-DD hh:mm:ss.fffffffff" for `seconds` after noon of `date` (YYYY_MM_DD).
std::string timestamp(const std::string& date, double seconds) {
  const auto total_ns = static_cast<long long>(std::llround(seconds * 1e9));
  const long long ns = total_ns % 1000000000LL, whole = total_ns / 1000000000LL;
  const long long hour = 12 + whole / 3600, minute = (whole / 60) % 60, second = whole % 60;
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%s-%s-%s %02lld:%02lld:%02lld.%09lld",
                date.substr(0, 4).c_str(), date.substr(5, 2).c_str(), date.substr(8, 2).c_str(),
                hour, minute, second, ns);
  return buffer;
}

void validateOptions(const KittiExportOptions& o) {
  const std::string& d = o.date;
  const bool date_ok =
      d.size() == 10 && d[4] == '_' && d[7] == '_' &&
      std::all_of(d.begin(), d.end(), [](char c) { return c == '_' || std::isdigit(c); });
  if (!date_ok) throw std::invalid_argument("KITTI export: date must be YYYY_MM_DD, got " + d);
  if (o.drive < 0 || o.drive > 9999) throw std::invalid_argument("KITTI export: drive 0..9999");
  if (o.num_frames < 1) throw std::invalid_argument("KITTI export: num_frames must be >= 1");
}

}  // namespace

void writeKittiCalibration(const std::string& date_dir, const StereoCamera& camera,
                           const Eigen::Isometry3d& T_cam_lidar) {
  camera.validate();
  createDirectories(date_dir);
  const double fx = camera.fx, fy = camera.fy, cx = camera.cx, cy = camera.cy;
  const std::string size = numbers({double(camera.width), double(camera.height)});
  const std::string k = numbers({fx, 0, cx, 0, fy, cy, 0, 0, 1});
  const std::string identity = numbers({1, 0, 0, 0, 1, 0, 0, 0, 1});
  const std::string p_left = numbers({fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0});
  const std::string p_right = numbers({fx, 0, cx, -fx * camera.baseline, 0, fy, cy, 0, 0, 0, 1, 0});
  const std::string no_distortion = numbers({0, 0, 0, 0, 0});

  const fs::path cam_path = fs::path(date_dir) / "calib_cam_to_cam.txt";
  std::ofstream cam = openForWriting(cam_path);
  cam << "calib_time: 01-Jan-2000 12:00:00\n";
  cam << "corner_dist: " << numbers({0.0995}) << "\n";
  // Cameras 0/1 (grey) and 2/3 (colour) coincide in this synthetic rig: 0 = 2 = left, 1 = 3 =
  // right. The images are already rectified, so K = the rectified intrinsics, D = 0, R = I.
  for (int i = 0; i < 4; ++i) {
    const bool right = (i % 2) == 1;
    const std::string id = "0" + std::to_string(i);
    cam << "S_" << id << ": " << size << "\n";
    cam << "K_" << id << ": " << k << "\n";
    cam << "D_" << id << ": " << no_distortion << "\n";
    cam << "R_" << id << ": " << identity << "\n";
    cam << "T_" << id << ": " << numbers({right ? -camera.baseline : 0.0, 0, 0}) << "\n";
    cam << "S_rect_" << id << ": " << size << "\n";
    cam << "R_rect_" << id << ": " << identity << "\n";
    cam << "P_rect_" << id << ": " << (right ? p_right : p_left) << "\n";
  }
  closeChecked(cam, cam_path);

  const fs::path velo_path = fs::path(date_dir) / "calib_velo_to_cam.txt";
  std::ofstream velo = openForWriting(velo_path);
  velo << "calib_time: 01-Jan-2000 12:00:00\n";
  velo << "R: " << matrixRowMajor(T_cam_lidar.linear()) << "\n";
  velo << "T: " << matrixRowMajor(T_cam_lidar.translation()) << "\n";
  velo << "delta_f: " << numbers({0, 0}) << "\n";
  velo << "delta_c: " << numbers({0, 0}) << "\n";
  closeChecked(velo, velo_path);
}

void writeKittiFrame(const std::string& drive_dir, int index, const SyntheticFrame& frame) {
  const fs::path root(drive_dir);
  const std::string name = frameName(index);
  const fs::path left = root / "image_02" / "data", right = root / "image_03" / "data";
  const fs::path velo = root / "velodyne_points" / "data";
  const fs::path gt = root / "proj_depth" / "groundtruth" / "image_02";
  for (const fs::path& dir : {left, right, velo, gt}) createDirectories(dir);
  writePng(left / (name + ".png"), frame.left);
  writePng(right / (name + ".png"), frame.right);
  kitti::writeVelodyneBin((velo / (name + ".bin")).string(), frame.cloud);
  kitti::writeDepthPng((gt / (name + ".png")).string(), frame.depth);
}

std::string writeKittiDrive(const std::string& root, const SyntheticParams& params,
                            const KittiExportOptions& options) {
  params.validate();
  validateOptions(options);
  char drive_name[64];
  std::snprintf(drive_name, sizeof(drive_name), "%s_drive_%04d_sync", options.date.c_str(),
                options.drive);
  const fs::path date_dir = fs::path(root) / options.date;
  const fs::path drive_dir = date_dir / drive_name;
  writeKittiCalibration(date_dir.string(), params.camera(), params.cameraFromLidar());

  std::vector<std::string> stamps, starts, ends;
  for (int i = 0; i < options.num_frames; ++i) {
    const SyntheticFrame frame = generateStreetFrame(params, i);
    writeKittiFrame(drive_dir.string(), i, frame);
    // The sweep starts facing forward at the frame's stamp, when the cameras are triggered.
    stamps.push_back(timestamp(options.date, frame.stamp));
    starts.push_back(stamps.back());
    ends.push_back(timestamp(options.date, frame.stamp + params.frame_period));
  }
  const auto writeLines = [](const fs::path& path, const std::vector<std::string>& lines) {
    std::ofstream out = openForWriting(path);
    for (const std::string& line : lines) out << line << "\n";
    closeChecked(out, path);
  };
  writeLines(drive_dir / "image_02" / "timestamps.txt", stamps);
  writeLines(drive_dir / "image_03" / "timestamps.txt", stamps);
  writeLines(drive_dir / "velodyne_points" / "timestamps.txt", stamps);
  writeLines(drive_dir / "velodyne_points" / "timestamps_start.txt", starts);
  writeLines(drive_dir / "velodyne_points" / "timestamps_end.txt", ends);
  return drive_dir.string();
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
