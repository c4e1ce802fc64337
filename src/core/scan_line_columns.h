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

/// Algorithm 1 as removeOccludedPoints (upsampling.h), returning the column index of the lines it
/// leaves: the index it decided on, with the cleared pixels erased (no second pass over the map).
ColumnIndex removeOccludedPointsIndexed(ScanLines& lines, const cv::Mat& image,
                                        const BIParams& params, std::vector<cv::Point>& removed);

/// removeParallaxHidden (upsampling.h) on `index` (that of `lines`): clears the pixels, erases
/// them from the index and merges them into `removed` (ordered by column, then row, as Algorithm
/// 1 leaves it).
void removeParallaxHiddenIndexed(ScanLines& lines, ColumnIndex& index, const StereoCamera& camera,
                                 const Eigen::Vector3d& lidar_origin, const BIParams& params,
                                 std::vector<cv::Point>& removed);

cv::Mat1f interpolateBetweenScanLines(const ColumnIndex& index, const cv::Mat1f& lines,
                                      const BIParams& params);

ScanLineBounds computeScanLineBounds(const ColumnIndex& index, const cv::Mat1f& lines,
                                     double margin_px);

cv::Mat1f priorConfidence(const ColumnIndex& index, const cv::Mat1f& lines, const cv::Mat1f& prior,
                          const std::vector<cv::Point>& removed,
                          const PriorConfidenceParams& params);

/// The readings of prior_confidence.h per interval between two lines of a column, set up once per
/// map: the agreement of the interval and the factor of the distance to the nearer line.
class IntervalConfidence {
 public:
  /// `removed`: the pixels Algorithm 1 cleared (x = column, y = row; any order; outside `size`
  /// ignored). `params` must be valid.
  IntervalConfidence(const PriorConfidenceParams& params, const cv::Size& size,
                     const std::vector<cv::Point>& removed);
  /// agree of column x's interval between its entries k and k + 1 (`e`: the column's n entries):
  /// exp(-max(0, r - edge_tolerance) / edge_sigma), times removed_factor when Algorithm 1 cleared
  /// a pixel strictly inside it.
  float agreement(const ColumnEntry* e, int n, int k, int x) const;
  /// The factor at `rows` rows from the nearer line (0 <= rows <= the map's rows / 2).
  float nearness(int rows) const { return near_[static_cast<size_t>(rows)]; }

 private:
  float tolerance_, inv_sigma_, max_slope_, removed_factor_;
  std::vector<float> near_;
  std::vector<std::vector<int>> removed_rows_;  ///< by column, each sorted
};

/// Outputs of scanLineIntervals; a null pointer is not computed.
struct IntervalMaps {
  cv::Mat1f* prior = nullptr;        ///< Eq. 3: interpolateBetweenScanLines
  ScanLineBounds* bounds = nullptr;  ///< computeScanLineBounds(margin_px)
  /// the prior's confidence (prior_confidence.h); needs a model
  cv::Mat1f* confidence = nullptr;
};

/// Stage 2's maps that follow each column's intervals between scan lines, in one row-major pass
/// (a column walk writes a cache line per pixel, and each map walked the lines on its own): every
/// output pixel is written (rig 1280x720, 128 rings: 3.4 ms a view for the three, against 6.1).
/// interpolateBetweenScanLines, computeScanLineBounds and priorConfidence are this pass. The
/// confidence is of BI*'s own Eq. 3 unless `prior_of_confidence` gives another prior (BF*'s):
/// then where it has a value and which intervals it bridges are read from it, and out.prior is
/// not written. Checks nothing: the callers have.
void scanLineIntervals(const ColumnIndex& index, const cv::Mat1f& lines, int max_interp_rows,
                       double margin_px, const IntervalConfidence* confidence_model,
                       const IntervalMaps& out, const cv::Mat1f* prior_of_confidence = nullptr);

}  // namespace lidar_stereo_fusion
