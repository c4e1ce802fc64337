#include "lidar_stereo_fusion/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <boost/make_shared.hpp>
#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {
namespace conversions {

namespace enc = sensor_msgs::image_encodings;
using sensor_msgs::PointField;

const std::vector<std::string>& supportedImageEncodings() {
  static const std::vector<std::string> kEncodings = {enc::BGRA8, enc::RGBA8, enc::BGR8, enc::RGB8,
                                                      enc::MONO8};
  return kEncodings;
}

namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

bool isSupported(const std::string& encoding) {
  const auto& all = supportedImageEncodings();
  return std::find(all.begin(), all.end(), encoding) != all.end();
}

}  // namespace

std::string checkImage(const sensor_msgs::Image& msg) {
  std::ostringstream problem;
  if (!isSupported(msg.encoding)) {
    problem << "unsupported encoding '" << msg.encoding
            << "' (supported: " << joined(supportedImageEncodings()) << ")";
  } else if (msg.width == 0 || msg.height == 0) {
    problem << "empty image (" << msg.width << "x" << msg.height << ")";
  } else if (static_cast<uint64_t>(msg.width) * enc::numChannels(msg.encoding) >
                 static_cast<uint64_t>(std::numeric_limits<int>::max()) ||
             msg.height > static_cast<uint32_t>(std::numeric_limits<int>::max())) {
    // 64-bit arithmetic: width * channels wraps in 32 bits for widths near 2^30.
    problem << "image of " << msg.width << "x" << msg.height << " " << msg.encoding
            << " is too large (width * channels and height must fit in an int)";
  } else if (static_cast<uint64_t>(msg.step) <
             static_cast<uint64_t>(msg.width) * enc::numChannels(msg.encoding)) {
    problem << "step " << msg.step << " is smaller than width * channels for " << msg.encoding;
  } else if (msg.data.size() < static_cast<size_t>(msg.step) * msg.height) {
    problem << "data has " << msg.data.size() << " bytes, step * height needs "
            << static_cast<size_t>(msg.step) * msg.height;
  }
  return problem.str();
}

cv::Mat imageToCore(const sensor_msgs::ImageConstPtr& msg) {
  const std::string problem = checkImage(*msg);
  if (!problem.empty()) throw ConversionError(problem);
  cv_bridge::CvImageConstPtr shared;
  try {
    shared = cv_bridge::toCvShare(msg);
  } catch (const cv_bridge::Exception& e) {
    throw ConversionError(std::string("cv_bridge: ") + e.what());
  } catch (const cv::Exception& e) {
    throw ConversionError(std::string("cv_bridge (OpenCV): ") + e.what());
  }
  const std::string& e = msg->encoding;
  cv::Mat out;
  try {
    if (e == enc::BGR8 || e == enc::MONO8) {
      out = shared->image.clone();  // own the pixels: the message may go before the result
    } else if (e == enc::BGRA8) {
      cv::cvtColor(shared->image, out, cv::COLOR_BGRA2BGR);
    } else if (e == enc::RGBA8) {
      cv::cvtColor(shared->image, out, cv::COLOR_RGBA2BGR);
    } else {  // rgb8
      cv::cvtColor(shared->image, out, cv::COLOR_RGB2BGR);
    }
  } catch (const cv::Exception& ex) {  // OpenCV's own checks: never let them escape a callback
    throw ConversionError(std::string("OpenCV: ") + ex.what());
  }
  return out;
}

sensor_msgs::ImagePtr decompressImage(const sensor_msgs::CompressedImage& msg) {
  const std::string described = "compressed image (format '" + msg.format + "', " +
                                std::to_string(msg.data.size()) + " bytes)";
  // cv_bridge reads data[0] unchecked, and cannot read the 12-byte header of compressedDepth.
  if (msg.data.empty()) throw ConversionError("empty " + described);
  if (msg.format.find("compressedDepth") != std::string::npos) {
    throw ConversionError(described + " is a compressedDepth depth map, not a camera image");
  }
  cv_bridge::CvImagePtr decoded;
  try {
    decoded = cv_bridge::toCvCopy(msg);
  } catch (const cv_bridge::Exception& e) {
    throw ConversionError("cannot decode " + described + ": cv_bridge: " + e.what());
  } catch (const cv::Exception& e) {
    throw ConversionError("cannot decode " + described + ": OpenCV: " + e.what());
  }
  if (!decoded || decoded->image.empty()) {
    throw ConversionError("cannot decode " + described + ": not a png or jpeg image OpenCV reads");
  }
  if (decoded->image.depth() != CV_8U) {
    throw ConversionError(described + " decodes to " +
                          std::to_string(decoded->image.elemSize1() * 8) +
                          "-bit pixels; the stereo pair must be 8-bit");
  }
  sensor_msgs::ImagePtr out = decoded->toImageMsg();
  out->header = msg.header;
  return out;
}

void stereoPairToCore(const sensor_msgs::ImageConstPtr& left,
                      const sensor_msgs::ImageConstPtr& right, cv::Mat& left_out,
                      cv::Mat& right_out, std::string* note) {
  if (note != nullptr) note->clear();
  if (left->width != right->width || left->height != right->height) {
    std::ostringstream s;
    s << "left image is " << left->width << "x" << left->height << " but right image is "
      << right->width << "x" << right->height << " (the pair must be rectified to one size)";
    throw ConversionError(s.str());
  }
  left_out = imageToCore(left);
  right_out = imageToCore(right);
  if (left_out.type() != right_out.type()) {  // one mono8, one colour: both grey
    // Grey replicated into three channels would be matched against real colours; the colour
    // view's grey is what the mono camera would have seen.
    if (left_out.channels() == 3) cv::cvtColor(left_out, left_out, cv::COLOR_BGR2GRAY);
    if (right_out.channels() == 3) cv::cvtColor(right_out, right_out, cv::COLOR_BGR2GRAY);
    if (note != nullptr) {
      *note = "left image is " + left->encoding + " but right image is " + right->encoding +
              ": both views are matched as grey (publish one encoding to match colours)";
    }
  }
}

StereoCamera stereoCameraFromInfo(const sensor_msgs::CameraInfo& left,
                                  const sensor_msgs::CameraInfo& right) {
  const auto& Pl = left.P;
  const auto& Pr = right.P;
  for (std::size_t i : {0u, 2u, 3u, 5u, 6u}) {  // the entries used below, of both cameras
    if (!std::isfinite(Pl[i]) || !std::isfinite(Pr[i])) {
      throw CameraInfoError(!std::isfinite(Pl[i]),
                            std::string(std::isfinite(Pl[i]) ? "right" : "left") +
                                " camera_info: P[" + std::to_string(i) + "] is " +
                                std::to_string(std::isfinite(Pl[i]) ? Pr[i] : Pl[i]) +
                                " (not finite); is the camera calibrated?");
    }
  }
  if (Pl[0] <= 0.0 || Pl[5] <= 0.0) {
    throw CameraInfoError(true,
                          "left camera_info: P has no focal length (fx = " + std::to_string(Pl[0]) +
                              ", fy = " + std::to_string(Pl[5]) + "); is the camera calibrated?");
  }
  if (Pr[0] <= 0.0) {
    throw CameraInfoError(false, "right camera_info: P has no focal length (fx = " +
                                     std::to_string(Pr[0]) + "); is the camera calibrated?");
  }
  if (std::abs(Pl[0] - Pr[0]) > 1e-3 * Pl[0] || std::abs(Pl[5] - Pr[5]) > 1e-3 * Pl[5]) {
    throw CameraInfoError(false, "left and right camera_info P differ in focal length (fx " +
                                     std::to_string(Pl[0]) + " vs " + std::to_string(Pr[0]) +
                                     "): images are not rectified to a common camera");
  }
  if (left.width != right.width || left.height != right.height) {
    throw CameraInfoError(false, "left camera_info is " + std::to_string(left.width) + "x" +
                                     std::to_string(left.height) + " but right camera_info is " +
                                     std::to_string(right.width) + "x" +
                                     std::to_string(right.height));
  }
  StereoCamera camera;
  camera.fx = Pl[0];
  camera.fy = Pl[5];
  camera.cx = Pl[2];
  camera.cy = Pl[6];
  // Tx = P[3] = -fx * B for the right camera in the ROS convention (left Tx = 0); some drivers
  // write +fx * B. The difference of the two Tx is independent of the reference camera.
  camera.baseline = std::abs(Pr[3] - Pl[3]) / Pl[0];
  camera.width = static_cast<int>(left.width);
  camera.height = static_cast<int>(left.height);
  if (!(camera.baseline > 0.0) || !std::isfinite(camera.baseline)) {
    throw CameraInfoError(
        false, "right camera_info: P[3] (Tx = -fx * baseline) is " + std::to_string(Pr[3]) +
                   ", equal to the left one: no baseline (is this the right camera's info?)");
  }
  const std::string implausible = baselinePlausibilityProblem(camera.baseline);
  if (!implausible.empty()) {
    throw CameraInfoError(
        false, "right camera_info: P[3] = " + std::to_string(Pr[3]) + " gives a " + implausible);
  }
  return camera;
}

bool hostIsBigEndian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

// -------------------------------------------------------------------------------------------------
// Outputs
// -------------------------------------------------------------------------------------------------
namespace {

sensor_msgs::Image floatImage(const cv::Mat1f& image, const std_msgs::Header& header) {
  sensor_msgs::Image msg;
  msg.header = header;
  msg.height = static_cast<uint32_t>(image.rows);
  msg.width = static_cast<uint32_t>(image.cols);
  msg.encoding = enc::TYPE_32FC1;
  msg.is_bigendian = hostIsBigEndian();
  msg.step = msg.width * sizeof(float);
  msg.data.resize(static_cast<size_t>(msg.step) * msg.height);
  for (int r = 0; r < image.rows; ++r) {
    std::memcpy(msg.data.data() + static_cast<size_t>(r) * msg.step, image.ptr<float>(r), msg.step);
  }
  return msg;
}

}  // namespace

stereo_msgs::DisparityImagePtr disparityToMsg(const cv::Mat1f& disparity,
                                              const std_msgs::Header& header,
                                              const StereoCamera& camera, double min_search,
                                              double max_search) {
  auto msg = boost::make_shared<stereo_msgs::DisparityImage>();
  msg->header = header;
  msg->image = floatImage(disparity, header);
  msg->f = static_cast<float>(camera.fx);
  msg->T = static_cast<float>(camera.baseline);
  // The configured search range, as stereo_image_proc (not the values of this frame). Values
  // outside it (LiDAR-only methods: very far or very near points) are published as 0 = no value,
  // which is below min_disparity as long as the range starts above 0.
  const double min_d = min_search > 0.0 ? min_search : 1.0;
  const double max_d = std::max(max_search, min_d);
  float* data = reinterpret_cast<float*>(msg->image.data.data());
  int left = disparity.cols, top = disparity.rows, right = -1, bottom = -1;
  for (int r = 0; r < disparity.rows; ++r) {
    float* row = data + static_cast<size_t>(r) * disparity.cols;
    for (int c = 0; c < disparity.cols; ++c) {
      const float d = row[c];
      if (!(d >= min_d && d <= max_d)) {  // also NaN and 0
        row[c] = 0.f;
        continue;
      }
      left = std::min(left, c);
      right = std::max(right, c);
      top = std::min(top, r);
      bottom = std::max(bottom, r);
    }
  }
  if (right >= 0) {
    msg->valid_window.x_offset = static_cast<uint32_t>(left);
    msg->valid_window.y_offset = static_cast<uint32_t>(top);
    msg->valid_window.width = static_cast<uint32_t>(right - left + 1);
    msg->valid_window.height = static_cast<uint32_t>(bottom - top + 1);
  }
  msg->min_disparity = static_cast<float>(min_d);
  msg->max_disparity = static_cast<float>(max_d);
  // PatchMatch planes give continuous disparities; 1/16 px is the nominal step stereo_image_proc
  // publishes and below the accuracy of the refinement (which stops at 0.1 px).
  msg->delta_d = 1.f / 16.f;
  return msg;
}

sensor_msgs::ImagePtr depthToMsg(const cv::Mat1f& depth, const std_msgs::Header& header,
                                 double max_depth) {
  auto msg = boost::make_shared<sensor_msgs::Image>(floatImage(depth, header));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float limit =
      max_depth > 0.0 ? static_cast<float>(max_depth) : std::numeric_limits<float>::infinity();
  float* data = reinterpret_cast<float*>(msg->data.data());
  const size_t n = static_cast<size_t>(depth.rows) * depth.cols;
  for (size_t i = 0; i < n; ++i) {
    if (!(data[i] > 0.f) || !(data[i] <= limit)) data[i] = nan;
  }
  return msg;
}

sensor_msgs::ImagePtr bgrImageToMsg(const cv::Mat& image, const std_msgs::Header& header) {
  if (image.type() != CV_8UC3) throw ConversionError("bgrImageToMsg: image must be CV_8UC3");
  return cv_bridge::CvImage(header, sensor_msgs::image_encodings::BGR8, image).toImageMsg();
}

sensor_msgs::ImagePtr floatImageToMsg(const cv::Mat1f& image, const std_msgs::Header& header) {
  return boost::make_shared<sensor_msgs::Image>(floatImage(image, header));
}

sensor_msgs::PointCloud2Ptr organizedCloudToMsg(const cv::Mat1f& depth, const cv::Mat& image,
                                                const StereoCamera& camera, int stride,
                                                const std_msgs::Header& header) {
  if (stride < 1) throw std::invalid_argument("organizedCloudToMsg: stride must be >= 1");
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
  msg->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*msg);
  modifier.setPointCloud2Fields(4, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT32, "z", 1,
                                PointField::FLOAT32, "rgb", 1, PointField::FLOAT32);
  if (msg->point_step != kPackedPointBytes) {  // packOrganizedCloud's layout is the modifier's
    throw std::logic_error("organizedCloudToMsg: x, y, z, rgb take " +
                           std::to_string(msg->point_step) + " bytes, not " +
                           std::to_string(kPackedPointBytes));
  }
  const uint32_t width = static_cast<uint32_t>((depth.cols + stride - 1) / stride);
  const uint32_t height = static_cast<uint32_t>((depth.rows + stride - 1) / stride);
  // resize(w * h) makes it 1 x N; the organised shape is set after.
  modifier.resize(static_cast<size_t>(width) * height);
  msg->height = height;
  msg->width = width;
  msg->row_step = msg->width * msg->point_step;
  msg->is_dense = packOrganizedCloud(depth, image, camera, stride, msg->data.data());
  return msg;
}

}  // namespace conversions
}  // namespace lidar_stereo_fusion
