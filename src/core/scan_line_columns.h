// Stage 2's column steps on one ColumnIndex: upsampleView (pipeline.cpp) builds the index once,
// after Algorithm 1, for Eq. 3, the search bounds and the prior's confidence (one build takes 1.2
// ms on the rig, 1280x720 with 128 rings; KITTI frame 0's stage 2: 1-1.7 ms less). The functions of
// upsampling.h and prior_confidence.h build an index of their own and call these; the checks are
// here. `index` must be ColumnIndex(lines) of the `lines` given. Private to the core.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "column_index.h"
#include "lidar_stereo_fusion/core/prior_confidence.h"
#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {

cv::Mat1f interpolateBetweenScanLines(const ColumnIndex& index, const cv::Mat1f& lines,
                                      const BIParams& params);

ScanLineBounds computeScanLineBounds(const ColumnIndex& index, const cv::Mat1f& lines,
                                     double margin_px);

cv::Mat1f priorConfidence(const ColumnIndex& index, const cv::Mat1f& lines, const cv::Mat1f& prior,
                          const std::vector<cv::Point>& removed,
                          const PriorConfidenceParams& params);

}  // namespace lidar_stereo_fusion
