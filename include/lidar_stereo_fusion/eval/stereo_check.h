// A LiDAR-made depth reference cleaned with stereo, as KITTI's depth-completion ground truth is
// (Uhrig et al., 3DV 2017: the accumulated sweeps' outliers removed where a stereo reconstruction
// of the frame disagrees). Here the stereo is OpenCV's StereoSGBM with the settings this package
// benchmarks against; a reference pixel stays when SGBM has a disparity there within
// max_diff_px of the reference's. ROS-free.
//
// Why a reference needs it: an accumulated reference favours the foreground at depth edges (the
// nearest of up to 11 sweeps' points wins a pixel, and a LiDAR beam a few mrad wide returns the
// foreground when it grazes an edge), so it is wider than the image's objects by a pixel or so;
// the stereo check removes most such pixels, and with them the pixels the stereo cannot see
// (occlusions, no texture): the kept ones are where LiDAR and images agree.
#pragma once

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// What the stereo check removed.
struct StereoCheckCounts {
  int checked = 0;              ///< reference pixels looked at
  int removed_no_stereo = 0;    ///< of them: SGBM has no disparity there
  int removed_disagreeing = 0;  ///< of them: SGBM's disparity differs by more than max_diff_px
};

/// OpenCV's StereoSGBM as fusion_benchmark times it (MODE_SGBM_3WAY, 128 disparities, block 5,
/// P1 = 8 * 3 * 25, P2 = 32 * 3 * 25, uniqueness 10, speckle window 100 / range 32).
cv::Ptr<cv::StereoSGBM> referenceSgbm();

/// SGBM's disparity of a rectified pair [px], 0 where it has none.
cv::Mat1f sgbmDisparity(const cv::Mat& left, const cv::Mat& right);

/// Removes from `depth` [m] (0 = no reference) the pixels where `stereo_disparity` [px] (0 = none)
/// is missing or differs from the reference's disparity fx * baseline / z by more than
/// max_diff_px. Throws std::invalid_argument for sizes that differ, an invalid camera or a
/// max_diff_px that is not positive and finite.
StereoCheckCounts removeStereoOutliers(cv::Mat1f& depth, const cv::Mat1f& stereo_disparity,
                                       const StereoCamera& camera, double max_diff_px);

}  // namespace lidar_stereo_fusion
