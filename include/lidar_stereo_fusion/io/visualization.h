// Pictures a person can look at: colourised disparity / depth / error maps. ROS-free.
#pragma once

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"

namespace lidar_stereo_fusion {

/// Colourises disparity [px] with a perceptual colour map scaled to [0, max_disparity]
/// (max_disparity <= 0: the map's own maximum); empty pixels (0) are black. Returns BGR8.
cv::Mat colorizeDisparity(const cv::Mat1f& disparity, double max_disparity = 0.0);

/// Colourises depth [m] (near = warm), empty (0 / NaN) black. Returns BGR8.
cv::Mat colorizeDepth(const cv::Mat1f& depth, double max_depth = 80.0);

/// Absolute error |estimate - reference| in px, clipped at max_error, only where the reference has
/// a value (elsewhere black); a reference pixel without estimate shows as max_error. Returns BGR8.
cv::Mat colorizeError(const cv::Mat1f& estimate, const cv::Mat1f& reference,
                      double max_error = 5.0);

/// Colourises the prior's confidence [0, 1] (VIRIDIS: dark violet = 0, yellow = 1) where `prior`
/// has a value; black where it has none (confidence 0 by definition). Returns BGR8.
cv::Mat colorizeConfidence(const cv::Mat1f& confidence, const cv::Mat1f& prior);

/// `picture` (BGR8) with a colour bar below it, so that its colours can be read as values: the
/// colour map `colormap` from level 0 (left) to 255 (right), labelled at five places with the
/// value that level stands for (`value_at_0` .. `value_at_255`, linear) and `unit` ("m", "px").
/// The colorize* functions above map: disparity 0 .. max -> 0 .. 255 (TURBO), depth max .. 0 m ->
/// 0 .. 255 (TURBO), error 0 .. max px -> 0 .. 255 (TURBO), confidence 0 .. 1 -> 0 .. 255
/// (VIRIDIS). Black, as in the picture, means no value.
cv::Mat withColorBar(const cv::Mat& picture, double value_at_0, double value_at_255,
                     const std::string& unit, int colormap = cv::COLORMAP_TURBO);

/// The top [px] of a frame's disparity colour scale: the 99th percentile of its disparities (> 0)
/// rounded up to a multiple of 16 px (16 px when it has none), at most `max_search` (the top of
/// the search range). The search range (192 px) or a few near outliers as the top would leave a
/// street's 5-60 px in one colour; disparities above the top take the top colour.
double disparityColorScale(const cv::Mat1f& disparity, double max_search);

/// The live node's disparity_image_color: colorizeDisparity on [0, disparityColorScale] with a
/// colour bar in px. Returns BGR8, taller than `disparity` by the bar.
cv::Mat disparityPicture(const cv::Mat1f& disparity, double max_search);

/// The live node's depth/image_color: colorizeDepth on [0, max_depth] [m] (near = warm) with a
/// colour bar in m. Returns BGR8, taller than `depth` by the bar.
cv::Mat depthPicture(const cv::Mat1f& depth, double max_depth);

/// Draws sparse LiDAR disparity as coloured dots over a darkened copy of `image`. Returns BGR8.
cv::Mat overlaySparse(const cv::Mat& image, const cv::Mat1f& sparse, double max_disparity = 0.0);

}  // namespace lidar_stereo_fusion
