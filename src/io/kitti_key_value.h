// Internal to src/io: the "key: v0 v1 ..." text of KITTI's calibration files
// (calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt). Not installed.
#pragma once

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

namespace lidar_stereo_fusion {
namespace kitti {
namespace detail {

/// "key: v0 v1 ..." lines of a KITTI calibration file, values kept as text until asked for.
class KeyValueFile {
 public:
  explicit KeyValueFile(const std::string& path) : path_(path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("KITTI calibration: cannot open " + path);
    std::string line;
    while (std::getline(in, line)) {
      const auto colon = line.find(':');
      if (colon == std::string::npos) continue;
      values_[trim(line.substr(0, colon))] = line.substr(colon + 1);
    }
  }

  /// Exactly `count` numbers of `key`; throws naming file and key otherwise.
  std::vector<double> numbers(const std::string& key, size_t count) const {
    const auto it = values_.find(key);
    if (it == values_.end()) {
      throw std::runtime_error("KITTI calibration: " + path_ + " has no key '" + key + "'");
    }
    std::istringstream in(it->second);
    std::vector<double> out;
    std::string token;
    while (in >> token) {
      size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size() || !std::isfinite(value)) {
        throw std::runtime_error("KITTI calibration: " + path_ + " key '" + key +
                                 "' has a value that is not a finite number: '" + token + "'");
      }
      out.push_back(value);
    }
    if (out.size() != count) {
      throw std::runtime_error("KITTI calibration: " + path_ + " key '" + key + "' has " +
                               std::to_string(out.size()) + " values, expected " +
                               std::to_string(count));
    }
    return out;
  }

  const std::string& path() const { return path_; }

 private:
  static std::string trim(const std::string& s) {
    const auto first = s.find_first_not_of(" \t\r");
    if (first == std::string::npos) return "";
    const auto last = s.find_last_not_of(" \t\r");
    return s.substr(first, last - first + 1);
  }

  std::string path_;
  std::map<std::string, std::string> values_;
};

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> readMatrix(const KeyValueFile& file, const std::string& key) {
  const std::vector<double> v = file.numbers(key, Rows * Cols);
  Eigen::Matrix<double, Rows, Cols> m;
  for (int r = 0; r < Rows; ++r) {
    for (int c = 0; c < Cols; ++c) m(r, c) = v[r * Cols + c];  // KITTI stores row-major
  }
  return m;
}

inline void requireRotation(const Eigen::Matrix3d& r, const std::string& file,
                            const std::string& key) {
  const double orthogonality =
      (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-4 || std::abs(r.determinant() - 1.0) > 1e-4) {
    throw std::runtime_error("KITTI calibration: " + file + " key '" + key +
                             "' is not a rotation matrix");
  }
}

}  // namespace detail
}  // namespace kitti
}  // namespace lidar_stereo_fusion
