// Stage 4: disparity -> depth (z = fx B / d) and the coloured point cloud of the left view.
#include "lidar_stereo_fusion/core/depth.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {
namespace {

bool hasValue(float v) { return std::isfinite(v) && v > 0.f; }

void requireCameraSize(const cv::Mat& map, const StereoCamera& camera, const char* who) {
  camera.validate();
  if (map.empty()) throw std::invalid_argument(std::string(who) + ": empty input map");
  if (camera.width > 0 && (map.cols != camera.width || map.rows != camera.height)) {
    throw std::invalid_argument(std::string(who) + ": map is " + std::to_string(map.cols) + "x" +
                                std::to_string(map.rows) + " but the camera is " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

}  // namespace

cv::Mat1f disparityToDepth(const cv::Mat1f& disparity, const StereoCamera& camera,
                           double max_depth) {
  requireCameraSize(disparity, camera, "disparityToDepth");
  if (!(max_depth >= 0.0)) {
    throw std::invalid_argument("disparityToDepth: max_depth must be >= 0 (0 = no limit)");
  }
  const double fb = camera.fx * camera.baseline;
  cv::Mat1f depth(disparity.size(), 0.f);
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = disparity(y, x);
      if (!hasValue(d)) continue;
      const double z = fb / d;
      if (max_depth > 0.0 && z > max_depth) continue;
      depth(y, x) = static_cast<float>(z);
    }
  }
  return depth;
}

cv::Mat1f depthToDisparity(const cv::Mat1f& depth, const StereoCamera& camera) {
  requireCameraSize(depth, camera, "depthToDisparity");
  const double fb = camera.fx * camera.baseline;
  cv::Mat1f disparity(depth.size(), 0.f);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth(y, x);
      if (hasValue(z)) disparity(y, x) = static_cast<float>(fb / z);
    }
  }
  return disparity;
}

namespace {

void checkCloudInputs(const cv::Mat1f& depth, const cv::Mat& image, const StereoCamera& camera,
                      int stride, const char* what) {
  requireCameraSize(depth, camera, what);
  if (image.size() != depth.size()) {
    throw std::invalid_argument(std::string(what) + ": image is " + std::to_string(image.cols) +
                                "x" + std::to_string(image.rows) + " but depth is " +
                                std::to_string(depth.cols) + "x" + std::to_string(depth.rows));
  }
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    throw std::invalid_argument(std::string(what) + ": image must be BGR CV_8UC3 or grey CV_8UC1");
  }
  if (stride < 1) throw std::invalid_argument(std::string(what) + ": stride must be >= 1");
}

/// Calls emit(x, y, z, b, g, r) for each point of the grid (every `stride`-th row and column),
/// row-major: X = (x - cx) z / fx, Y = (y - cy) z / fy on row pointers, with x, y, z NaN where the
/// pixel has no depth. One walker for the three clouds; the organised ones run on every frame of
/// the live node (points2 is as large as stereo_image_proc's).
template <class Emit>
void forEachGridPoint(const cv::Mat1f& depth, const cv::Mat& image, const StereoCamera& camera,
                      int stride, Emit&& emit) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const bool colour = image.type() == CV_8UC3;
  for (int y = 0; y < depth.rows; y += stride) {
    const float* z_row = depth.ptr<float>(y);
    const uint8_t* pixels = image.ptr<uint8_t>(y);
    for (int x = 0; x < depth.cols; x += stride) {
      const float z = z_row[x];
      const bool has = hasValue(z);
      const float px = has ? static_cast<float>((x - camera.cx) * z / camera.fx) : nan;
      const float py = has ? static_cast<float>((y - camera.cy) * z / camera.fy) : nan;
      if (colour) {
        const uint8_t* bgr = pixels + 3 * x;
        emit(px, py, has ? z : nan, bgr[0], bgr[1], bgr[2]);
      } else {
        emit(px, py, has ? z : nan, pixels[x], pixels[x], pixels[x]);
      }
    }
  }
}

}  // namespace

std::vector<ColoredPoint> makeColoredCloud(const cv::Mat1f& depth, const cv::Mat& image,
                                           const StereoCamera& camera, int stride) {
  checkCloudInputs(depth, image, camera, stride, "makeColoredCloud");
  std::vector<ColoredPoint> cloud;
  forEachGridPoint(depth, image, camera, stride,
                   [&](float x, float y, float z, uint8_t b, uint8_t g, uint8_t r) {
                     if (!std::isnan(z)) cloud.push_back(ColoredPoint{x, y, z, r, g, b});
                   });
  return cloud;
}

OrganizedCloud makeOrganizedCloud(const cv::Mat1f& depth, const cv::Mat& image,
                                  const StereoCamera& camera, int stride) {
  checkCloudInputs(depth, image, camera, stride, "makeOrganizedCloud");
  OrganizedCloud cloud;
  cloud.width = (depth.cols + stride - 1) / stride;
  cloud.height = (depth.rows + stride - 1) / stride;
  cloud.points.resize(static_cast<size_t>(cloud.width) * cloud.height);
  ColoredPoint* out = cloud.points.data();
  forEachGridPoint(depth, image, camera, stride,
                   [&](float x, float y, float z, uint8_t b, uint8_t g, uint8_t r) {
                     *out++ = ColoredPoint{x, y, z, r, g, b};
                   });
  return cloud;
}

bool packOrganizedCloud(const cv::Mat1f& depth, const cv::Mat& image, const StereoCamera& camera,
                        int stride, uint8_t* out) {
  checkCloudInputs(depth, image, camera, stride, "packOrganizedCloud");
  bool dense = true;
  forEachGridPoint(depth, image, camera, stride,
                   [&](float x, float y, float z, uint8_t b, uint8_t g, uint8_t r) {
                     const float xyz[3] = {x, y, z};
                     std::memcpy(out, xyz, sizeof(xyz));
                     out[12] = b;
                     out[13] = g;
                     out[14] = r;
                     out[15] = 0;
                     out += kPackedPointBytes;
                     dense = dense && !std::isnan(z);
                   });
  return dense;
}

}  // namespace lidar_stereo_fusion
