// kitti_runner's output folder (tools/kitti_runner.cpp): created and checked before the first
// frame, and the pictures of --save-vis.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/pipeline.h"

namespace kitti_runner {

/// Creates `dir` (and its parents); throws std::runtime_error naming it when that fails.
void createDirectory(const std::filesystem::path& dir);

/// Throws std::runtime_error naming both when `out` is `input` or lies inside it (symbolic links
/// resolved): kitti_runner never writes among the files it reads (into a drive's image_02/data
/// its PNGs would replace the recording's images). `what` names the input ("--kitti-raw").
void requireApart(const std::filesystem::path& out, const std::filesystem::path& input,
                  const std::string& what);

/// Fails now, with the reason, when `dir` cannot take files (not after the first frame).
void requireWritable(const std::filesystem::path& dir);

/// --save-vis: writes <dir>/<name>_{sparse,prior,confidence,disparity,depth,error}.png of one
/// frame, each with a colour bar in its unit (the prior and its confidence only when the method
/// has a prior, the error only with a `reference` depth [m]).
void saveVisualisation(const std::filesystem::path& dir, const std::string& name,
                       const cv::Mat& left, const lidar_stereo_fusion::FusionResult& result,
                       const std::optional<cv::Mat1f>& reference,
                       const lidar_stereo_fusion::StereoCamera& camera);

}  // namespace kitti_runner
