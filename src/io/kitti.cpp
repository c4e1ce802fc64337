// KITTI raw layout (calibration, .bin sweeps, timestamps) and KITTI depth-completion PNGs.
#include "lidar_stereo_fusion/io/kitti.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"

#include "kitti_key_value.h"  // src/io internal

namespace lidar_stereo_fusion {
namespace kitti {
namespace {

namespace fs = std::filesystem;
using detail::KeyValueFile;
using detail::readMatrix;
using detail::requireRotation;

constexpr int kHdl64Rings = 64;  ///< KITTI's Velodyne HDL-64E

/// P = K [I | t]: checks K is an upper-triangular pinhole matrix with fx, fy > 0.
void requireRectifiedProjection(const Eigen::Matrix<double, 3, 4>& p, const std::string& file,
                                const std::string& key) {
  const bool pinhole =
      p(0, 0) > 0 && p(1, 1) > 0 && p(1, 0) == 0 && p(2, 0) == 0 && p(2, 1) == 0 && p(2, 2) == 1.0;
  if (!pinhole) {
    throw std::runtime_error("KITTI calibration: " + file + " key '" + key +
                             "' is not a rectified projection K [I | t] with fx, fy > 0");
  }
}

StereoCamera cameraFromProjections(const Eigen::Matrix<double, 3, 4>& p2,
                                   const Eigen::Matrix<double, 3, 4>& p3,
                                   const std::vector<double>& size, const std::string& file) {
  if ((p2.leftCols<3>() - p3.leftCols<3>()).cwiseAbs().maxCoeff() > 1e-6) {
    throw std::runtime_error("KITTI calibration: " + file +
                             " P_rect_02 and P_rect_03 have different intrinsics; the images are "
                             "not a rectified pair");
  }
  StereoCamera camera;
  camera.fx = p2(0, 0);
  camera.fy = p2(1, 1);
  camera.cx = p2(0, 2);
  camera.cy = p2(1, 2);
  // P_rect_0i[0, 3] = -fx * b_i with b_i the x position of camera i in the rectified cam-0 frame:
  // b_3 - b_2 = (P2[0, 3] - P3[0, 3]) / fx.
  camera.baseline = (p2(0, 3) - p3(0, 3)) / camera.fx;
  // Checked before the conversion: 4294968538 would wrap to 1242 in an int.
  for (const double v : size) {
    if (!(v >= 1.0 && v <= 100000.0) || v != std::floor(v)) {
      throw std::runtime_error("KITTI calibration: " + file + " key 'S_rect_02' is not a size " +
                               "(two integers in [1, 100000], got " + std::to_string(v) + ")");
    }
  }
  camera.width = static_cast<int>(size[0]);
  camera.height = static_cast<int>(size[1]);
  if (!(camera.baseline > 0)) {
    throw std::runtime_error("KITTI calibration: " + file +
                             " P_rect_03 is not to the right of P_rect_02 (baseline " +
                             std::to_string(camera.baseline) + " m)");
  }
  if (camera.width <= 0 || camera.height <= 0) {
    throw std::runtime_error("KITTI calibration: " + file + " key 'S_rect_02' is not a size");
  }
  const std::string implausible = baselinePlausibilityProblem(camera.baseline);
  if (!implausible.empty()) {
    throw std::runtime_error("KITTI calibration: " + file + " P_rect_02 / P_rect_03 give a " +
                             implausible);
  }
  return camera;
}

std::string requireFile(const fs::path& path, const std::string& what) {
  if (!fs::is_regular_file(path)) {
    throw std::runtime_error("KITTI: missing " + what + " " + path.string());
  }
  return path.string();
}

cv::Mat readColorImage(const std::string& path) {
  // IMREAD_COLOR reduces a 16-bit PNG to 8 bits without a word (a 16-bit pair came out as if it
  // were black): read what is there and scale explicitly.
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw std::runtime_error("KITTI: cannot read image " + path);
  if (image.depth() == CV_16U) {
    image.convertTo(image, CV_8U, 255.0 / 65535.0);
  } else if (image.depth() != CV_8U) {
    throw std::runtime_error("KITTI: image " + path +
                             " is neither 8 nor 16 bits per channel (OpenCV depth " +
                             std::to_string(image.depth()) + ")");
  }
  if (image.channels() == 1) {
    cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  } else if (image.channels() != 3) {
    throw std::runtime_error("KITTI: image " + path + " has " + std::to_string(image.channels()) +
                             " channels");
  }
  return image;
}

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
int64_t daysFromCivil(int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<int64_t>(doe) - 719468;
}

/// "2011-09-26 13:02:25.964389445" -> seconds since the epoch; false when malformed.
bool parseTimestamp(const std::string& line, double& seconds) {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0, used = 0;
  if (std::sscanf(line.c_str(), "%4d-%2d-%2d %2d:%2d:%2d%n", &year, &month, &day, &hour, &minute,
                  &second, &used) != 6) {
    return false;
  }
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60) {
    return false;
  }
  double fraction = 0.0;
  std::string rest = line.substr(used);
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\r')) rest.pop_back();
  if (!rest.empty()) {
    if (rest[0] != '.' || rest.size() < 2) return false;
    double scale = 0.1;
    for (size_t i = 1; i < rest.size(); ++i) {
      if (rest[i] < '0' || rest[i] > '9') return false;
      fraction += (rest[i] - '0') * scale;
      scale *= 0.1;
    }
  }
  const int64_t days =
      daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day));
  seconds = static_cast<double>(days * 86400 + hour * 3600 + minute * 60 + second) + fraction;
  return true;
}

}  // namespace

Calibration readCalibration(const std::string& dir) {
  const KeyValueFile cam(requireFile(fs::path(dir) / "calib_cam_to_cam.txt", "calibration file"));
  const KeyValueFile velo(requireFile(fs::path(dir) / "calib_velo_to_cam.txt", "calibration file"));

  Calibration calib;
  calib.P2 = readMatrix<3, 4>(cam, "P_rect_02");
  calib.P3 = readMatrix<3, 4>(cam, "P_rect_03");
  requireRectifiedProjection(calib.P2, cam.path(), "P_rect_02");
  requireRectifiedProjection(calib.P3, cam.path(), "P_rect_03");
  const Eigen::Matrix3d r_rect = readMatrix<3, 3>(cam, "R_rect_00");
  requireRotation(r_rect, cam.path(), "R_rect_00");
  calib.camera = cameraFromProjections(calib.P2, calib.P3, cam.numbers("S_rect_02", 2), cam.path());

  const Eigen::Matrix3d r_velo = readMatrix<3, 3>(velo, "R");
  requireRotation(r_velo, velo.path(), "R");
  const Eigen::Vector3d t_velo = readMatrix<3, 1>(velo, "T");

  Eigen::Isometry3d velo_to_cam0 = Eigen::Isometry3d::Identity();
  velo_to_cam0.linear() = r_velo;
  velo_to_cam0.translation() = t_velo;
  Eigen::Isometry3d rect = Eigen::Isometry3d::Identity();
  rect.linear() = r_rect;
  // t_2 = K^-1 P_rect_02[:, 3]: the rectified cam-0 origin in cam 2's frame (about +0.06 m in x).
  const Eigen::Vector3d t_cam2 = calib.P2.leftCols<3>().inverse() * calib.P2.col(3);
  calib.T_cam_velo = Eigen::Translation3d(t_cam2) * rect * velo_to_cam0;
  return calib;
}

LidarCloud readVelodyneBin(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error("KITTI: cannot open Velodyne sweep " + path);
  const std::streamoff bytes = in.tellg();
  if (bytes < 0 || bytes % 16 != 0) {
    throw std::runtime_error("KITTI: Velodyne sweep " + path + " has " + std::to_string(bytes) +
                             " bytes, not a multiple of 16 (float32 x, y, z, reflectance)");
  }
  std::vector<float> raw(static_cast<size_t>(bytes / 4));
  in.seekg(0);
  if (!raw.empty() && !in.read(reinterpret_cast<char*>(raw.data()), bytes)) {
    throw std::runtime_error("KITTI: cannot read Velodyne sweep " + path);
  }
  LidarCloud cloud(raw.size() / 4);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud[i].x = raw[4 * i];
    cloud[i].y = raw[4 * i + 1];
    cloud[i].z = raw[4 * i + 2];
    cloud[i].intensity = raw[4 * i + 3];
  }
  return cloud;
}

void writeVelodyneBin(const std::string& path, const LidarCloud& cloud) {
  std::vector<float> raw;
  raw.reserve(cloud.size() * 4);
  for (const LidarPoint& p : cloud) raw.insert(raw.end(), {p.x, p.y, p.z, p.intensity});
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("KITTI: cannot create " + path);
  out.write(reinterpret_cast<const char*>(raw.data()),
            static_cast<std::streamsize>(raw.size() * sizeof(float)));
  if (!out) throw std::runtime_error("KITTI: cannot write " + path);
}

cv::Mat1f readDepthPng(const std::string& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error("KITTI: missing depth PNG " + path);
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw std::runtime_error("KITTI: cannot read depth PNG " + path);
  if (raw.type() != CV_16UC1) {
    throw std::runtime_error("KITTI: depth PNG " + path +
                             " is not single-channel uint16 (KITTI format: metres * 256)");
  }
  cv::Mat1f depth;
  raw.convertTo(depth, CV_32F, 1.0 / 256.0);
  return depth;
}

void writeDepthPng(const std::string& path, const cv::Mat1f& depth_m) {
  if (depth_m.empty()) throw std::invalid_argument("writeDepthPng: empty depth map for " + path);
  cv::Mat_<uint16_t> raw(depth_m.size(), uint16_t{0});
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const float z = depth_m(y, x);
      if (!std::isfinite(z) || z <= 0.f) continue;
      // Round to 1/256 m; clamp into [1, 65535] so that a tiny depth never becomes "none" and
      // depths beyond 255.996 m saturate (the format's limit).
      const double v = std::round(static_cast<double>(z) * 256.0);
      raw(y, x) = static_cast<uint16_t>(std::clamp(v, 1.0, 65535.0));
    }
  }
  bool ok = false;
  try {
    ok = cv::imwrite(path, raw);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("KITTI: cannot write depth PNG " + path + ": " + e.what());
  }
  if (!ok) throw std::runtime_error("KITTI: cannot write depth PNG " + path);
}

std::vector<Frame> listFrames(const std::string& drive_dir, std::vector<std::string>* incomplete) {
  const fs::path root(drive_dir);
  const fs::path left_dir = root / "image_02" / "data";
  if (!fs::is_directory(left_dir)) {
    throw std::runtime_error("KITTI: " + drive_dir + " is not a raw drive folder (no " +
                             left_dir.string() + ")");
  }
  std::vector<Frame> frames;
  for (const auto& entry : fs::directory_iterator(left_dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".png") continue;
    const std::string name = entry.path().stem().string();
    Frame frame;
    frame.name = name;
    frame.left_image = entry.path().string();
    frame.right_image = (root / "image_03" / "data" / (name + ".png")).string();
    frame.velodyne = (root / "velodyne_points" / "data" / (name + ".bin")).string();
    const bool right = fs::is_regular_file(frame.right_image);
    const bool velodyne = fs::is_regular_file(frame.velodyne);
    if (right && velodyne) {
      frames.push_back(frame);
    } else if (incomplete != nullptr) {
      incomplete->push_back("frame " + name + ": missing " +
                            (right ? frame.velodyne : frame.right_image) +
                            (!right && !velodyne ? " and " + frame.velodyne : ""));
    }
  }
  if (incomplete != nullptr) std::sort(incomplete->begin(), incomplete->end());
  std::sort(frames.begin(), frames.end(),
            [](const Frame& a, const Frame& b) { return a.name < b.name; });
  return frames;
}

FrameData loadFrame(const Frame& frame, const StereoCamera& camera) {
  FrameData data;
  data.left = readColorImage(frame.left_image);
  data.right = readColorImage(frame.right_image);
  if (data.left.size() != data.right.size()) {
    throw std::runtime_error("KITTI: frame " + frame.name +
                             ": image sizes differ: " + frame.left_image + " is " +
                             std::to_string(data.left.cols) + "x" + std::to_string(data.left.rows) +
                             ", " + frame.right_image + " is " + std::to_string(data.right.cols) +
                             "x" + std::to_string(data.right.rows));
  }
  if (camera.width > 0 && (data.left.cols != camera.width || data.left.rows != camera.height)) {
    throw std::runtime_error("KITTI: frame " + frame.name + ": image " + frame.left_image + " is " +
                             std::to_string(data.left.cols) + "x" + std::to_string(data.left.rows) +
                             " but the calibration (S_rect_02) says " +
                             std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  data.cloud = readVelodyneBin(frame.velodyne);
  data.rings = ensureRings(data.cloud, /*has_ring_field=*/false, kHdl64Rings);
  return data;
}

std::string calibrationDirOf(const std::string& drive_dir) {
  fs::path path(drive_dir);
  if (!path.has_filename()) path = path.parent_path();  // trailing slash
  const fs::path parent = path.parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

std::vector<double> readTimestamps(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("KITTI: cannot open timestamps " + path);
  std::vector<double> stamps;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) {
      // KITTI leaves a line empty for a dropped sample (drive 0009, Velodyne 177-180): keep the
      // index of every later frame.
      stamps.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    double seconds = 0.0;
    if (!parseTimestamp(line, seconds)) {
      throw std::runtime_error("KITTI: " + path + " line " + std::to_string(line_number) +
                               " is not a timestamp 'YYYY-MM-DD hh:mm:ss.fffffffff': '" + line +
                               "'");
    }
    stamps.push_back(seconds);
  }
  return stamps;
}

}  // namespace kitti
}  // namespace lidar_stereo_fusion
