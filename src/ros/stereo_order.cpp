#include "lidar_stereo_fusion/ros/stereo_order.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool names(const std::string& frame, const char* side) {
  return lower(frame).find(side) != std::string::npos;
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", v);
  return text;
}

cv::Mat greyHalved(const cv::Mat& image, int max_width) {
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  while (grey.cols > max_width) cv::pyrDown(grey, grey);
  return grey;
}

}  // namespace

StereoOrder infoOrder(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right,
                      std::string* evidence) {
  const double left_tx = left.P[3], right_tx = right.P[3];
  if (evidence != nullptr) {
    *evidence = "left camera_info P[3] = " + number(left_tx) +
                ", right camera_info P[3] = " + number(right_tx);
  }
  if (left_tx != 0.0 && right_tx == 0.0) return StereoOrder::kSwapped;
  if (left_tx == 0.0 && right_tx != 0.0) return StereoOrder::kInOrder;
  return StereoOrder::kUnknown;  // both 0 (refused elsewhere) or both set (e.g. KITTI's)
}

StereoOrder frameOrder(const std::string& left_frame, const std::string& right_frame,
                       std::string* evidence) {
  if (evidence != nullptr) {
    *evidence = "left frame_id '" + left_frame + "', right frame_id '" + right_frame + "'";
  }
  const bool left_says_right = names(left_frame, "right") && !names(left_frame, "left");
  const bool right_says_left = names(right_frame, "left") && !names(right_frame, "right");
  if (left_says_right && right_says_left) return StereoOrder::kSwapped;
  return StereoOrder::kUnknown;
}

StereoOrder ImageOrderCount::verdict() const {
  const int decided = positive + negative;
  if (pixels <= 0 || decided < pixels / 200) return StereoOrder::kUnknown;
  if (negative >= 4 * positive) return StereoOrder::kSwapped;
  if (positive >= 4 * negative) return StereoOrder::kInOrder;
  return StereoOrder::kUnknown;
}

ImageOrderCount imageOrder(const cv::Mat& left, const cv::Mat& right) {
  if (left.size() != right.size() || left.type() != right.type() || left.depth() != CV_8U ||
      (left.channels() != 1 && left.channels() != 3)) {
    throw std::invalid_argument("imageOrder: two 8-bit BGR or grey images of one size expected");
  }
  // Half size until at most 640 px wide: enough texture for a verdict, a few ms of matching.
  const cv::Mat l = greyHalved(left, 640), r = greyHalved(right, 640);
  constexpr int kBlock = 9;
  // Disparities up to an eighth of the width either way (a multiple of 16, as StereoBM needs).
  const int reach = std::max(16, (l.cols / 8 + 15) / 16 * 16);
  ImageOrderCount count;
  if (l.cols < 2 * reach + kBlock || l.rows < kBlock) return count;  // too small to say
  auto matcher = cv::StereoBM::create(2 * reach, kBlock);
  matcher->setMinDisparity(-reach);
  matcher->setUniquenessRatio(15);
  matcher->setTextureThreshold(10);
  cv::Mat disparity;  // CV_16S, 16 x px; (minDisparity - 1) * 16 where nothing matched
  matcher->compute(l, r, disparity);
  count.pixels = l.rows * l.cols;
  for (int y = 0; y < disparity.rows; ++y) {
    const int16_t* row = disparity.ptr<int16_t>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const int d = row[x];
      if (d < -reach * 16) continue;  // no match
      if (d > 16) ++count.positive;
      if (d < -16) ++count.negative;
    }
  }
  return count;
}

boost::optional<std::string> StereoOrderWatch::observe(const ImageSet& set) {
  if (decided_) return boost::none;
  ++sets_;
  std::string info_text, frame_text;
  const StereoOrder infos = infoOrder(*set.left_info, *set.right_info, &info_text);
  const StereoOrder frames =
      frameOrder(set.left->header.frame_id, set.right->header.frame_id, &frame_text);
  try {
    cv::Mat left, right;
    conversions::stereoPairToCore(set.left, set.right, left, right);
    const ImageOrderCount c = imageOrder(left, right);
    images_.positive += c.positive;
    images_.negative += c.negative;
    images_.pixels += c.pixels;
  } catch (const std::exception&) {  // the frame path names unusable images
  }
  if (images_.verdict() == StereoOrder::kUnknown && infos != StereoOrder::kSwapped &&
      sets_ < kMaxSets) {
    return boost::none;  // look at the next set
  }
  decided_ = true;
  return conclude(infos, frames, info_text, frame_text);
}

boost::optional<std::string> StereoOrderWatch::conclude(StereoOrder infos, StereoOrder frames,
                                                        const std::string& info_text,
                                                        const std::string& frame_text) {
  const StereoOrder images = images_.verdict();
  const std::string image_text = "block matching found " + std::to_string(images_.negative) +
                                 " pixels at negative disparity and " +
                                 std::to_string(images_.positive) + " at positive";
  const std::string fix =
      "swap the left and right inputs: left/image_rect_color:=" + topics_.right_image +
      " right/image_rect_color:=" + topics_.left_image;
  const std::string info_fix =
      "left/camera_info:=" + topics_.right_info + " right/camera_info:=" + topics_.left_info;
  if (images == StereoOrder::kSwapped) {
    std::string text =
        "the stereo pair looks swapped (the left topics carry the right camera): " + image_text +
        " (a pair in order matches at positive disparity)";
    if (infos == StereoOrder::kSwapped) text += "; " + info_text + " (the left one should be 0)";
    if (frames == StereoOrder::kSwapped) text += "; " + frame_text;
    // Camera_infos in order (the left one's P[3] is 0) stay; else they go with their images.
    return text + "; stereo and fused depth are wrong by metres: " + fix +
           (infos == StereoOrder::kInOrder ? " (the camera_infos are in order: " + info_text + ")"
                                           : " " + info_fix);
  }
  if (infos == StereoOrder::kSwapped) {
    return "the camera_infos look swapped: " + info_text +
           " (in the ROS convention the left camera's is 0 and the right one's -fx * baseline)" +
           (images == StereoOrder::kInOrder
                ? std::string("; the images are in order (") + image_text + "): " + info_fix
                : "; " + fix + " " + info_fix);
  }
  if (frames == StereoOrder::kSwapped && images == StereoOrder::kUnknown) {
    return "the stereo pair may be swapped: " + frame_text +
           " (the images gave no verdict: " + image_text + "); if so, " + fix + " " + info_fix;
  }
  return boost::none;
}

}  // namespace lidar_stereo_fusion
