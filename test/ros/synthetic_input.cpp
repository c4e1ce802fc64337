#include "synthetic_input.h"

#include <cstring>

#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>
#include <boost/make_shared.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {
namespace test {

namespace enc = sensor_msgs::image_encodings;

std::vector<sim::SyntheticFrame> makeFrames(int count, int width, int height, int rings,
                                            double azimuth_step_deg) {
  sim::SyntheticParams params;
  params = params.resized(width, height);
  params.rings = rings;
  params.azimuth_step_deg = azimuth_step_deg;
  params.subsamples = 2;
  std::vector<sim::SyntheticFrame> frames;
  for (int i = 0; i < count; ++i) frames.push_back(sim::generateStreetFrame(params, i));
  return frames;
}

sensor_msgs::ImagePtr imageMsg(const cv::Mat& bgr, const std::string& encoding,
                               const std::string& frame_id, const ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.frame_id = frame_id;
  msg->header.stamp = stamp;
  msg->width = static_cast<uint32_t>(bgr.cols);
  msg->height = static_cast<uint32_t>(bgr.rows);
  msg->encoding = encoding;
  cv::Mat converted;
  if (encoding == enc::BGR8) {
    converted = bgr;
  } else if (encoding == enc::RGB8) {
    cv::cvtColor(bgr, converted, cv::COLOR_BGR2RGB);
  } else if (encoding == enc::BGRA8) {
    cv::cvtColor(bgr, converted, cv::COLOR_BGR2BGRA);
  } else if (encoding == enc::RGBA8) {
    cv::cvtColor(bgr, converted, cv::COLOR_BGR2RGBA);
  } else if (encoding == enc::MONO8) {
    cv::cvtColor(bgr, converted, cv::COLOR_BGR2GRAY);
  } else {  // an encoding the nodelet must reject: a zero buffer of the right size
    const int bytes = enc::bitDepth(encoding) / 8 * enc::numChannels(encoding);
    msg->step = msg->width * static_cast<uint32_t>(bytes);
    msg->data.assign(static_cast<size_t>(msg->step) * msg->height, 0);
    return msg;
  }
  msg->step = static_cast<uint32_t>(converted.cols * converted.elemSize());
  msg->data.resize(static_cast<size_t>(msg->step) * msg->height);
  for (int r = 0; r < converted.rows; ++r) {
    std::memcpy(msg->data.data() + static_cast<size_t>(r) * msg->step, converted.ptr(r), msg->step);
  }
  return msg;
}

sensor_msgs::CameraInfoPtr cameraInfoMsg(const StereoCamera& camera, bool right,
                                         const std::string& frame_id, const ros::Time& stamp,
                                         bool positive_tx) {
  auto msg = boost::make_shared<sensor_msgs::CameraInfo>();
  msg->header.frame_id = frame_id;
  msg->header.stamp = stamp;
  msg->width = static_cast<uint32_t>(camera.width);
  msg->height = static_cast<uint32_t>(camera.height);
  msg->distortion_model = "plumb_bob";
  msg->D.assign(5, 0.0);
  msg->K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  msg->R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double tx = right ? (positive_tx ? 1.0 : -1.0) * camera.fx * camera.baseline : 0.0;
  msg->P = {camera.fx, 0, camera.cx, tx, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0};
  return msg;
}

sensor_msgs::PointCloud2Ptr cloudMsg(const LidarCloud& cloud, const std::string& frame_id,
                                     const ros::Time& stamp, bool with_ring) {
  std_msgs::Header header;
  header.frame_id = frame_id;
  header.stamp = stamp;
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>(conversions::cloudToMsg(cloud, header));
  if (!with_ring) {
    for (auto it = msg->fields.begin(); it != msg->fields.end(); ++it) {
      if (it->name == "ring") {
        msg->fields.erase(it);  // the bytes stay (padding), as in clouds with unknown fields
        break;
      }
    }
  }
  return msg;
}

geometry_msgs::TransformStamped lidarToCameraTf(const Eigen::Isometry3d& T_cam_lidar,
                                                const std::string& camera_frame,
                                                const std::string& lidar_frame) {
  geometry_msgs::TransformStamped tf = tf2::eigenToTransform(T_cam_lidar);
  tf.header.frame_id = camera_frame;
  tf.child_frame_id = lidar_frame;
  return tf;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
