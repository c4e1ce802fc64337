// Autoware camera-LiDAR calibration files (OpenCV FileStorage YAML).
#include "lidar_stereo_fusion/io/calibration_autoware.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <opencv2/core/eigen.hpp>

#include "lidar_stereo_fusion/io/text_file.h"

namespace lidar_stereo_fusion {
namespace {

/// Throws std::runtime_error naming the line when `text` is not laid out as the calibrator writes
/// it: the %YAML directive, "---", "Key: value" lines at column 0 and indented continuation lines
/// (matrix fields, wrapped data) below a key, blank lines and comments. OpenCV's YAML parser can
/// loop forever on some malformed input (found by fuzzing: a bare "5, -1," line before "---at:";
/// indented lines before any key), so files of another shape never reach it.
void requireAutowareLayout(const std::string& text, const std::string& path) {
  bool seen_key = false;
  forEachLine(text, [&](int number, std::string_view line) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) {
      line.remove_suffix(1);
    }
    if (line.empty() || line[0] == '#' || line == "---" ||
        ((line == "%YAML:1.0" || line == "%YAML 1.0") && number == 1)) {
      return;
    }
    if (line[0] == ' ' || line[0] == '\t') {
      if (seen_key) return;  // a continuation of the key above
      throw std::runtime_error("Autoware calibration " + path + ": line " + std::to_string(number) +
                               " is indented but no 'Key: value' line comes before it");
    }
    std::size_t key_end = 0;
    while (key_end < line.size() &&
           (std::isalnum(static_cast<unsigned char>(line[key_end])) || line[key_end] == '_')) {
      ++key_end;
    }
    const bool key_value = key_end > 0 && !std::isdigit(static_cast<unsigned char>(line[0])) &&
                           key_end < line.size() && line[key_end] == ':' &&
                           (key_end + 1 == line.size() || line[key_end + 1] == ' ');
    if (!key_value) {
      throw std::runtime_error("Autoware calibration " + path + ": line " + std::to_string(number) +
                               " is not 'Key: value' (" + std::string(line.substr(0, 40)) + ")");
    }
    seen_key = true;
  });
}

std::string where(const std::string& path, const std::string& key) {
  return "Autoware calibration " + path + ": key '" + key + "'";
}

/// A required !!opencv-matrix node converted to CV_64F with the given size (rows, cols > 0) or,
/// when rows == 0, any number of rows.
/// `node >> cv::Mat` with the checks OpenCV leaves out: it allocates rows x cols before it looks at
/// the data, so "rows: 2000000000" would allocate gigabytes; and its exceptions become ours.
cv::Mat readOpenCvMatrix(const cv::FileNode& node, const std::string& what) {
  const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
  // Without rows or cols OpenCV makes up a size (one fuzz input asked for 86 GB).
  if (!node.isMap() || !rows.isInt() || !cols.isInt() || !data.isSeq()) {
    throw std::runtime_error(what + " is not an opencv-matrix (rows, cols and data needed)");
  }
  const long long r = static_cast<int>(rows), c = static_cast<int>(cols);
  const long long values = static_cast<long long>(data.size());
  if (r < 0 || c < 0 || r * c > values) {
    throw std::runtime_error(what + " declares " + std::to_string(r) + "x" + std::to_string(c) +
                             " but has " + std::to_string(values) + " values");
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    m.release();
  }
  return m;
}

cv::Mat readMatrix(const cv::FileStorage& fs, const std::string& path, const std::string& key,
                   int rows, int cols) {
  const cv::FileNode node = fs[key];
  if (node.empty()) throw std::runtime_error(where(path, key) + " is missing");
  const cv::Mat m = readOpenCvMatrix(node, where(path, key));
  if (m.empty() || m.channels() != 1) {
    throw std::runtime_error(where(path, key) + " is not an opencv-matrix");
  }
  if ((rows > 0 && m.rows != rows) || m.cols != cols) {
    throw std::runtime_error(where(path, key) + " is " + std::to_string(m.rows) + "x" +
                             std::to_string(m.cols) + ", expected " +
                             (rows > 0 ? std::to_string(rows) : std::string("N")) + "x" +
                             std::to_string(cols));
  }
  cv::Mat out;
  m.convertTo(out, CV_64F);
  for (auto it = out.begin<double>(); it != out.end<double>(); ++it) {
    if (!std::isfinite(*it)) throw std::runtime_error(where(path, key) + " has a non-finite value");
  }
  return out;
}

Eigen::Isometry3d readExtrinsic(const cv::FileStorage& fs, const std::string& path) {
  const cv::Mat m = readMatrix(fs, path, "CameraExtrinsicMat", 4, 4);
  Eigen::Matrix4d e;
  cv::cv2eigen(m, e);
  const Eigen::Matrix3d r = e.topLeftCorner<3, 3>();
  const double orthogonality =
      (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const bool last_row_ok = (e.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() < 1e-9;
  if (orthogonality > 1e-4 || std::abs(r.determinant() - 1.0) > 1e-4 || !last_row_ok) {
    throw std::runtime_error(where(path, "CameraExtrinsicMat") +
                             " is not a rigid transform [R t; 0 0 0 1]");
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  t.translation() = e.topRightCorner<3, 1>();
  return t;
}

cv::Size readImageSize(const cv::FileStorage& fs, const std::string& path) {
  const cv::FileNode node = fs["ImageSize"];
  if (node.empty()) throw std::runtime_error(where(path, "ImageSize") + " is missing");
  if (!node.isSeq() || node.size() != 2 || !node[0].isInt() || !node[1].isInt()) {
    throw std::runtime_error(where(path, "ImageSize") + " is not [width, height]");
  }
  const cv::Size size(static_cast<int>(node[0]), static_cast<int>(node[1]));
  if (size.width <= 0 || size.height <= 0) {
    throw std::runtime_error(where(path, "ImageSize") + " is not positive");
  }
  return size;
}

std::vector<AutowareCalibration::Pair> readCalibData(const cv::FileStorage& fs,
                                                     const std::string& path) {
  std::vector<AutowareCalibration::Pair> pairs;
  if (fs["CalibData"].empty()) return pairs;
  const cv::Mat m = readMatrix(fs, path, "CalibData", 0, 5);
  for (int r = 0; r < m.rows; ++r) {
    const double* row = m.ptr<double>(r);
    pairs.push_back({row[0], row[1], row[2], row[3], row[4]});
  }
  return pairs;
}

/// Pinhole projection with plumb_bob (k1 k2 p1 p2 [k3]) or rational_polynomial
/// (k1 k2 p1 p2 k3 k4 k5 k6) distortion, as cv::projectPoints does with a zero pose.
cv::Point2d projectDistorted(const Eigen::Vector3d& p, const cv::Matx33d& k, const cv::Mat& dist) {
  double c[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < std::min<int>(8, static_cast<int>(dist.total())); ++i) {
    c[i] = dist.at<double>(i);
  }
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial =
      (1 + c[0] * r2 + c[1] * r4 + c[4] * r6) / (1 + c[5] * r2 + c[6] * r4 + c[7] * r6);
  const double xd = x * radial + 2 * c[2] * x * y + c[3] * (r2 + 2 * x * x);
  const double yd = y * radial + c[2] * (r2 + 2 * y * y) + 2 * c[3] * x * y;
  return {k(0, 0) * xd + k(0, 1) * yd + k(0, 2), k(1, 1) * yd + k(1, 2)};
}

}  // namespace

AutowareCalibration readAutowareCalibration(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("Autoware calibration: missing file " + path);
  }
  const std::string text = readTextFile(path, "Autoware calibration");
  requireTextFile(text, path, "Autoware calibration");
  requireAutowareLayout(text, path);
  requireYamlMarkersAlone(text, path, "Autoware calibration");
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("Autoware calibration " + path + ": not a valid OpenCV YAML file (" +
                             e.what() + ")");
  }
  if (!fs.isOpened()) throw std::runtime_error("Autoware calibration: cannot open " + path);

  AutowareCalibration calib;
  calib.T_lidar_cam = readExtrinsic(fs, path);
  const cv::Mat k = readMatrix(fs, path, "CameraMat", 3, 3);
  calib.camera_matrix = cv::Matx33d(k.ptr<double>());
  if (!(calib.camera_matrix(0, 0) > 0 && calib.camera_matrix(1, 1) > 0)) {
    throw std::runtime_error(where(path, "CameraMat") + " has non-positive focal lengths");
  }
  const cv::FileNode dist = fs["DistCoeff"];
  if (dist.empty()) throw std::runtime_error(where(path, "DistCoeff") + " is missing");
  const cv::Mat d = readOpenCvMatrix(dist, where(path, "DistCoeff"));
  if (d.empty() || (d.rows != 1 && d.cols != 1)) {
    throw std::runtime_error(where(path, "DistCoeff") + " is not a 1xN opencv-matrix");
  }
  d.reshape(1, 1).convertTo(calib.dist_coeffs, CV_64F);
  calib.image_size = readImageSize(fs, path);
  const cv::FileNode error = fs["ReprojectionError"];
  calib.reprojection_error = error.empty() ? -1.0 : static_cast<double>(error);
  const cv::FileNode model = fs["DistModel"];
  calib.dist_model = model.empty() ? std::string("plumb_bob") : static_cast<std::string>(model);
  calib.calib_data = readCalibData(fs, path);
  return calib;
}

cv::Point2d projectToImage(const AutowareCalibration& calib, const Eigen::Vector3d& p_cam) {
  if (calib.dist_model != "plumb_bob" && calib.dist_model != "rational_polynomial") {
    throw std::invalid_argument("projectToImage: unsupported DistModel '" + calib.dist_model +
                                "' (plumb_bob or rational_polynomial)");
  }
  if (!calib.dist_coeffs.empty() &&
      (calib.dist_coeffs.type() != CV_64FC1 || calib.dist_coeffs.total() > 8)) {
    throw std::invalid_argument("projectToImage: DistCoeff must be CV_64F with at most 8 values");
  }
  if (!(p_cam.z() > 0)) throw std::invalid_argument("projectToImage: point not in front (z <= 0)");
  return projectDistorted(p_cam, calib.camera_matrix, calib.dist_coeffs);
}

Eigen::Isometry3d cameraFromLidar(const AutowareCalibration& calib) {
  return calib.T_lidar_cam.inverse();
}

double meanReprojectionError(const AutowareCalibration& calib) {
  return meanReprojectionError(calib, cameraFromLidar(calib));
}

double meanReprojectionError(const AutowareCalibration& calib,
                             const Eigen::Isometry3d& T_cam_lidar) {
  if (calib.calib_data.empty()) {
    throw std::invalid_argument("meanReprojectionError: the calibration has no CalibData pairs");
  }
  double sum = 0.0;
  for (const auto& pair : calib.calib_data) {
    const Eigen::Vector3d p = T_cam_lidar * Eigen::Vector3d(pair.x, pair.y, pair.z);
    // A point behind the camera cannot be where it was clicked: infinitely wrong.
    if (p.z() <= 0) return std::numeric_limits<double>::infinity();
    const cv::Point2d pixel = projectToImage(calib, p);
    sum += std::hypot(pixel.x - pair.u, pixel.y - pair.v);
  }
  return sum / static_cast<double>(calib.calib_data.size());
}

}  // namespace lidar_stereo_fusion
