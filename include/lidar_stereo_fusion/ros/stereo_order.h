// Is the stereo pair the right way round? A pair whose left topics carry the right camera (swapped
// remaps, a driver's naming) is matched at the wrong sign of disparity: stereo finds nothing where
// it should and the fused depth is off by metres, with every frame "ok". Three kinds of evidence,
// each cheap, checked on the first image sets of a stream by the node (InputGate) and bag_runner
// (BagPairing), which warn once, naming the evidence and the fix:
//  * the camera_infos: in the ROS convention the left camera's P[3] (Tx) is 0 and the right one's
//    -fx * baseline (some drivers write +fx * baseline); a left Tx != 0 with a right Tx = 0 is a
//    swapped pair (both non-zero, as in KITTI's rectified infos, says nothing);
//  * the frame_ids: the left image's naming "right" and the right one's naming "left";
//  * the images: block matching (OpenCV's StereoBM) over negative and positive disparities. A
//    pair in order matches at positive disparity (left u against right u - d), a swapped pair at
//    negative disparity almost everywhere.
#pragma once

#include <string>

#include <boost/optional.hpp>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/ros/stereo_sync.h"

namespace lidar_stereo_fusion {

enum class StereoOrder { kUnknown, kInOrder, kSwapped };

/// From the camera_infos' P[3]; `evidence` (if given) says what was seen.
StereoOrder infoOrder(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right,
                      std::string* evidence = nullptr);

/// From the frame_ids (case-insensitive "left" / "right" in them).
StereoOrder frameOrder(const std::string& left_frame, const std::string& right_frame,
                       std::string* evidence = nullptr);

/// What block matching found over [-D, D) px (D about an eighth of the width) on the pair
/// reduced to at most 640 px wide: pixels matched at a disparity above +1 px and below -1 px.
struct ImageOrderCount {
  int positive = 0, negative = 0, pixels = 0;
  /// kSwapped when the negative matches outnumber the positive ones 4 to 1 (kInOrder the other
  /// way), with at least 0.5 % of the pixels matched; kUnknown otherwise (a flat or blank pair).
  StereoOrder verdict() const;
};
/// `left`, `right`: 8-bit BGR or grey images of one size (as conversions::imageToCore gives).
/// Throws std::invalid_argument on other types or sizes.
ImageOrderCount imageOrder(const cv::Mat& left, const cv::Mat& right);

/// The resolved input topics, to name the fix.
struct StereoTopics {
  std::string left_image, left_info, right_image, right_info;
};

/// Watches the first image sets of a stream and says, once, when the pair looks swapped.
class StereoOrderWatch {
 public:
  static constexpr int kMaxSets = 5;  ///< sets looked at before giving up without a verdict
  explicit StereoOrderWatch(StereoTopics topics) : topics_(std::move(topics)) {}
  /// Looks at `set` (checked by checkImageSet) until a verdict: the warning (once) when the
  /// evidence says swapped, naming it and the remaps that fix it; none otherwise.
  boost::optional<std::string> observe(const ImageSet& set);
  bool decided() const { return decided_; }

 private:
  boost::optional<std::string> conclude(StereoOrder infos, StereoOrder frames,
                                        const std::string& info_text,
                                        const std::string& frame_text);
  StereoTopics topics_;
  ImageOrderCount images_;  ///< summed over the sets seen
  int sets_ = 0;
  bool decided_ = false;
};

}  // namespace lidar_stereo_fusion
