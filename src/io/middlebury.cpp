// Middlebury scenes.
#include "lidar_stereo_fusion/io/middlebury.h"

#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace lidar_stereo_fusion {
namespace {

cv::Mat readImage(const std::string& path, int flags) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("Middlebury: missing file " + path);
  }
  cv::Mat image = cv::imread(path, flags);
  if (image.empty()) throw std::runtime_error("Middlebury: cannot read image " + path);
  return image;
}

}  // namespace

MiddleburyScene readMiddleburyScene(const std::string& dir, double disparity_scale) {
  if (!(disparity_scale > 0)) {
    throw std::invalid_argument("readMiddleburyScene: disparity_scale must be > 0");
  }
  const std::filesystem::path root(dir);
  MiddleburyScene scene;
  scene.left = readImage((root / "im2.png").string(), cv::IMREAD_COLOR);
  scene.right = readImage((root / "im6.png").string(), cv::IMREAD_COLOR);
  const std::string disp_path = (root / "disp2.png").string();
  const cv::Mat raw = readImage(disp_path, cv::IMREAD_UNCHANGED);
  if (raw.type() != CV_8UC1) {
    throw std::runtime_error("Middlebury: " + disp_path + " is not an 8-bit grey image");
  }
  if (scene.left.size() != scene.right.size() || raw.size() != scene.left.size()) {
    throw std::runtime_error("Middlebury: im2, im6 and disp2 in " + dir + " differ in size");
  }
  raw.convertTo(scene.disparity, CV_32F, 1.0 / disparity_scale);
  return scene;
}

}  // namespace lidar_stereo_fusion
