// Issue 33, the node's side without a ROS master (in test_ros_unit): compressed images decoded by
// the conversions the node and bag_runner share; the image transport chosen without ever needing
// a plugin that is not installed; a swapped stereo pair told by its camera_infos, frame_ids and
// images; remaps that name nothing of the node.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cv_bridge/cv_bridge.h>
#include <boost/make_shared.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/image_input.h"
#include "lidar_stereo_fusion/ros/node_support.h"
#include "lidar_stereo_fusion/ros/stereo_order.h"

namespace lsf = lidar_stereo_fusion;
namespace conv = lidar_stereo_fusion::conversions;

namespace {

constexpr int kSeed = 33;  ///< of the random textures

/// A random BGR texture (seeded).
cv::Mat texture(int width, int height, int seed = kSeed) {
  cv::RNG rng(seed);
  cv::Mat image(height, width, CV_8UC3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

sensor_msgs::CompressedImage compressed(const cv::Mat& image, const std::string& ext,
                                        const std::string& format) {
  sensor_msgs::CompressedImage msg;
  msg.header.frame_id = "left_camera_optical_frame";
  msg.header.stamp = ros::Time(12, 345);
  msg.format = format;
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(ext, image, bytes));
  msg.data.assign(bytes.begin(), bytes.end());
  return msg;
}

sensor_msgs::ImagePtr imageMsg(const cv::Mat& bgr, const std::string& frame) {
  auto msg = cv_bridge::CvImage(std_msgs::Header(), "bgr8", bgr).toImageMsg();
  msg->header.frame_id = frame;
  return msg;
}

sensor_msgs::CameraInfoPtr infoMsg(const cv::Mat& image, double tx) {
  auto msg = boost::make_shared<sensor_msgs::CameraInfo>();
  msg->width = static_cast<uint32_t>(image.cols);
  msg->height = static_cast<uint32_t>(image.rows);
  msg->P = {500, 0, image.cols / 2.0, tx, 0, 500, image.rows / 2.0, 0, 0, 0, 1, 0};
  return msg;
}

/// A rectified pair of a textured fronto-parallel wall at `disparity` px: left(u) = right(u - d).
std::pair<cv::Mat, cv::Mat> pair(int disparity, int width = 320, int height = 120) {
  const cv::Mat wide = texture(width + disparity, height);
  return {wide(cv::Rect(0, 0, width, height)).clone(),
          wide(cv::Rect(disparity, 0, width, height)).clone()};
}

lsf::ImageSet set(const cv::Mat& left, const cv::Mat& right, double left_tx, double right_tx,
                  const std::string& left_frame = "left_camera_optical_frame",
                  const std::string& right_frame = "right_camera_optical_frame") {
  lsf::ImageSet s;
  s.left = imageMsg(left, left_frame);
  s.right = imageMsg(right, right_frame);
  s.left_info = infoMsg(left, left_tx);
  s.right_info = infoMsg(right, right_tx);
  return s;
}

const lsf::StereoTopics kTopics = {"/cam/left/image", "/cam/left/info", "/cam/right/image",
                                   "/cam/right/info"};

}  // namespace

TEST(CompressedImages, PngDecodesToTheSamePixelsAndHeader) {
  const cv::Mat bgr = texture(37, 21);
  const auto out = conv::decompressImage(compressed(bgr, ".png", "bgr8; png compressed bgr8"));
  EXPECT_EQ(out->encoding, "bgr8");
  EXPECT_EQ(out->header.stamp, ros::Time(12, 345));
  EXPECT_EQ(out->header.frame_id, "left_camera_optical_frame");
  const cv::Mat back = conv::imageToCore(out);
  ASSERT_EQ(back.size(), bgr.size());
  EXPECT_EQ(cv::countNonZero(back.reshape(1) != bgr.reshape(1)), 0);
  cv::Mat grey(9, 11, CV_8UC1);
  cv::randu(grey, 0, 256);
  const auto mono = conv::decompressImage(compressed(grey, ".png", "mono8; png compressed mono8"));
  EXPECT_EQ(mono->encoding, "mono8");
  EXPECT_EQ(cv::countNonZero(conv::imageToCore(mono) != grey), 0);
}

TEST(CompressedImages, JpegDecodesCloseToTheOriginal) {
  cv::Mat smooth(48, 64, CV_8UC3);
  for (int y = 0; y < smooth.rows; ++y) {
    for (int x = 0; x < smooth.cols; ++x) smooth.at<cv::Vec3b>(y, x) = cv::Vec3b(2 * x, 3 * y, 90);
  }
  const auto out = conv::decompressImage(compressed(smooth, ".jpg", "rgb8; jpeg compressed bgr8"));
  EXPECT_EQ(out->encoding, "bgr8");
  cv::Mat diff;
  cv::absdiff(conv::imageToCore(out), smooth, diff);
  EXPECT_LT(cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2], 3 * 3.0);
}

TEST(CompressedImages, WhatCannotBeDecodedIsNamed) {
  sensor_msgs::CompressedImage empty;
  empty.format = "jpeg";
  EXPECT_THROW(
      {
        try {
          conv::decompressImage(empty);
        } catch (const conv::ConversionError& e) {
          EXPECT_NE(std::string(e.what()).find("empty compressed image"), std::string::npos);
          throw;
        }
      },
      conv::ConversionError);
  sensor_msgs::CompressedImage garbage = empty;
  garbage.data = {1, 2, 3, 4, 5, 6, 7, 8};
  try {
    conv::decompressImage(garbage);
    ADD_FAILURE() << "garbage decoded";
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot decode compressed image (format 'jpeg', 8 bytes)"),
              std::string::npos)
        << e.what();
  }
  sensor_msgs::CompressedImage depth = compressed(texture(8, 8), ".png", "16UC1; compressedDepth");
  EXPECT_THROW(conv::decompressImage(depth), conv::ConversionError);
  const cv::Mat deep(6, 7, CV_16UC1, cv::Scalar(1000));
  try {
    conv::decompressImage(compressed(deep, ".png", "mono16; png compressed mono16"));
    ADD_FAILURE() << "a 16-bit image decoded";
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("16-bit"), std::string::npos) << e.what();
  }
}

TEST(ImageTransport, CompressedWithoutItsPluginIsDecodedByTheNode) {
  const lsf::TransportChoice c = lsf::chooseTransport("compressed", {"image_transport/raw"});
  EXPECT_TRUE(c.decode_compressed);
  EXPECT_FALSE(c.error);
  EXPECT_NE(c.note.find("installed: raw"), std::string::npos) << c.note;
}

TEST(ImageTransport, AnInstalledPluginIsUsedAndAMissingOneNamedWithTheInstalled) {
  const lsf::TransportChoice plugin =
      lsf::chooseTransport("compressed", {"image_transport/raw", "image_transport/compressed"});
  EXPECT_FALSE(plugin.decode_compressed);
  EXPECT_EQ(plugin.transport, "compressed");
  const lsf::TransportChoice theora = lsf::chooseTransport("theora", {"image_transport/raw"});
  EXPECT_TRUE(theora.error);
  EXPECT_EQ(theora.transport, "raw");
  EXPECT_FALSE(theora.decode_compressed);
  EXPECT_NE(theora.note.find("'theora' is not installed (installed: raw"), std::string::npos)
      << theora.note;
  const lsf::TransportChoice raw = lsf::chooseTransport("", {});
  EXPECT_EQ(raw.transport, "raw");
  EXPECT_TRUE(raw.note.empty());
}

TEST(StereoOrder, CameraInfosTellWhichCameraIsWhich) {
  const cv::Mat image(10, 10, CV_8UC3);
  EXPECT_EQ(lsf::infoOrder(*infoMsg(image, 0.0), *infoMsg(image, -386.1)),
            lsf::StereoOrder::kInOrder);
  EXPECT_EQ(lsf::infoOrder(*infoMsg(image, 0.0), *infoMsg(image, 386.1)),
            lsf::StereoOrder::kInOrder);  // the +fx * B convention of some drivers
  std::string evidence;
  EXPECT_EQ(lsf::infoOrder(*infoMsg(image, -386.1), *infoMsg(image, 0.0), &evidence),
            lsf::StereoOrder::kSwapped);
  EXPECT_NE(evidence.find("left camera_info P[3] = -386.1"), std::string::npos) << evidence;
  // KITTI's rectified infos have a Tx in both: no verdict.
  EXPECT_EQ(lsf::infoOrder(*infoMsg(image, 44.9), *infoMsg(image, -339.5)),
            lsf::StereoOrder::kUnknown);
  EXPECT_EQ(lsf::frameOrder("zed_right_camera_optical_frame", "zed_left_camera_optical_frame"),
            lsf::StereoOrder::kSwapped);
  EXPECT_EQ(lsf::frameOrder("camera_left", "camera_right"), lsf::StereoOrder::kUnknown);
}

TEST(StereoOrder, BlockMatchingFindsTheSignOfTheDisparity) {
  const auto [left, right] = pair(12);
  const lsf::ImageOrderCount in_order = lsf::imageOrder(left, right);
  EXPECT_EQ(in_order.verdict(), lsf::StereoOrder::kInOrder)
      << in_order.positive << " positive, " << in_order.negative << " negative";
  EXPECT_GT(in_order.positive, in_order.pixels / 2);
  const lsf::ImageOrderCount swapped = lsf::imageOrder(right, left);
  EXPECT_EQ(swapped.verdict(), lsf::StereoOrder::kSwapped)
      << swapped.positive << " positive, " << swapped.negative << " negative";
  const cv::Mat flat(120, 320, CV_8UC3, cv::Scalar(80, 90, 100));
  EXPECT_EQ(lsf::imageOrder(flat, flat).verdict(), lsf::StereoOrder::kUnknown);
  EXPECT_THROW(lsf::imageOrder(left, cv::Mat(5, 5, CV_8UC3)), std::invalid_argument);
}

TEST(StereoOrder, TheWatchWarnsOnceNamingTheEvidenceAndTheFix) {
  const auto [left, right] = pair(12);
  lsf::StereoOrderWatch watch(kTopics);
  // The topics swapped: the "left" ones carry the right camera (its image, info and frame).
  const auto warning = watch.observe(
      set(right, left, -6000.0, 0.0, "right_camera_optical_frame", "left_camera_optical_frame"));
  ASSERT_TRUE(warning);
  EXPECT_TRUE(watch.decided());
  for (const char* part :
       {"looks swapped", "negative disparity", "left camera_info P[3] = -6000",
        "left frame_id 'right_camera_optical_frame'",
        "left/image_rect_color:=/cam/right/image right/image_rect_color:=/cam/left/image",
        "left/camera_info:=/cam/right/info right/camera_info:=/cam/left/info"}) {
    EXPECT_NE(warning->find(part), std::string::npos) << part << " in: " << *warning;
  }
  EXPECT_FALSE(watch.observe(set(right, left, -6000.0, 0.0)));  // once
  // Only the images swapped: the camera_infos stay.
  lsf::StereoOrderWatch images(kTopics);
  const auto only_images = images.observe(set(right, left, 0.0, -6000.0));
  ASSERT_TRUE(only_images);
  EXPECT_NE(only_images->find("left/image_rect_color:=/cam/right/image"), std::string::npos);
  EXPECT_EQ(only_images->find("left/camera_info:="), std::string::npos) << *only_images;
}

TEST(StereoOrder, APairInOrderGivesNoWarningAndAFlatOneNoVerdictAfterItsSets) {
  const auto [left, right] = pair(12);
  lsf::StereoOrderWatch in_order(kTopics);
  EXPECT_FALSE(in_order.observe(set(left, right, 0.0, -6000.0)));
  EXPECT_TRUE(in_order.decided());
  // The images in order but the camera_infos swapped: only the infos' remaps are the fix.
  lsf::StereoOrderWatch infos(kTopics);
  const auto warning = infos.observe(set(left, right, -6000.0, 0.0));
  ASSERT_TRUE(warning);
  EXPECT_NE(warning->find("camera_infos look swapped"), std::string::npos) << *warning;
  EXPECT_EQ(warning->find("left/image_rect_color:="), std::string::npos) << *warning;
  const cv::Mat flat(120, 320, CV_8UC3, cv::Scalar(80, 90, 100));
  lsf::StereoOrderWatch blank(kTopics);
  for (int i = 0; i < lsf::StereoOrderWatch::kMaxSets; ++i) {
    EXPECT_FALSE(blank.decided());
    EXPECT_FALSE(blank.observe(set(flat, flat, 0.0, -6000.0)));
  }
  EXPECT_TRUE(blank.decided());
}

TEST(Remaps, ATypoIsNamedWithTheNearestNameAndKnownNamesPass) {
  const std::map<std::string, std::string> remaps = {
      {"/fusion/left/image_rect", "/zed/left/image"},           // typo
      {"/fusion/left/image_rect_color", "/zed/left/image"},     // input
      {"/fusion/depth/image_rect", "/out/depth"},               // output
      {"/fusion/depth/image_rect/compressed", "/out/depth/c"},  // its transport topic
      {"/fusion/fusion/parameter_updates", "/elsewhere"},       // private
      {"/tf", "/tf_old"},                                       // ROS's own
      {"/velodyne_point", "/vls128/points"}};                   // typo, global
  const auto problems = lsf::unknownRemaps(remaps, "/fusion", "/fusion/fusion");
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("remap /fusion/left/image_rect := /zed/left/image names no topic"),
            std::string::npos)
      << problems[0];
  EXPECT_NE(problems[0].find("did you mean left/image_rect_color?"), std::string::npos);
  EXPECT_NE(problems[1].find("did you mean velodyne_points?"), std::string::npos) << problems[1];
  EXPECT_EQ(lsf::nearestName("confidance", lsf::outputNames()), "confidence");
  EXPECT_EQ(lsf::nearestName("something_else", lsf::outputNames()), "");
}
