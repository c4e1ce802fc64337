// Stage 2: up-sampling of the sparse LiDAR disparity into a dense prior.
//  BI* (the paper's method): horizontal scan-line completion, Algorithm 1 (removal of occluded
//      background points), linear interpolation between scan lines (Eq. 3).
//  BF* (Premebida et al. 2016): bilateral up-sampling, the paper's baseline.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"

namespace lidar_stereo_fusion {

struct BIParams {
  int max_gap_px = 12;         ///< completion does not bridge gaps wider than this [px]
  double max_jump_disp = 2.0;  ///< nor jumps in disparity larger than this [px]
  /// Across a larger jump (within max_gap_px) each pixel takes the nearer of the two points along
  /// the ring: a step in the middle, where the depth edge lies on average (false: a gap, the paper)
  bool step_fill = true;
  double max_disp_diff = 1.5;    ///< Algorithm 1 "Maxdisp": foreground must exceed d by this [px]
  double max_color_diff = 60.0;  ///< Algorithm 1 "Maxcolor": RGB L1 distance [0..765]
  int search_lines = 2;  ///< Algorithm 1 looks at this many scan lines up and down (paper: 1)
  /// After Algorithm 1, clear a scan-line pixel that the nearer scan line next to it in its column
  /// more likely than not hides from the camera, for the images to decide (removeParallaxHidden;
  /// the fused methods, with the LiDAR's pose: FusionPipeline::process). false: the paper.
  bool remove_parallax_hidden = true;
  int max_interp_rows = 60;  ///< Eq. 3 does not bridge scan lines further apart than this [rows]
  void validate() const;
};

struct BFParams {
  static constexpr int kMaxRadius = 255;     ///< [px] largest radius (core/param_table.h)
  static constexpr double kMinSigma = 1e-6;  ///< [px] smallest sigma (keeps the tables finite)
  int radius = 6;                            ///< half window [px]
  double sigma_space = 4.0;                  ///< spatial Gaussian sigma [px]
  double sigma_range = 2.0;  ///< disparity-range Gaussian sigma [px] (against the nearest point)
  int min_support = 1;       ///< pixels with fewer LiDAR neighbours stay empty
  void validate() const;
};

/// Scan lines after horizontal completion: one value per (ring, column) at most.
struct ScanLines {
  cv::Mat1f disparity;  ///< [px], 0 = no scan line at this pixel
  cv::Mat1s ring;       ///< ring of the line at this pixel, -1 elsewhere
};

/// BI* step 1: interpolates each ring linearly along x between consecutive projected points
/// (sorted by x): for x0 < x < x1, d = d0 + t (d1 - d0) and row = round(y0 + t (y1 - y0)),
/// t = (x - x0) / (x1 - x0). Neighbours are bridged only when x1 - x0 <= max_gap_px and
/// |d1 - d0| <= max_jump_disp; with step_fill, neighbours within max_gap_px across a larger jump
/// are bridged by a step: x - x0 < (x1 - x0) / 2 takes d0, beyond the middle d1, the middle
/// itself the larger (row interpolated as above). Where two lines hit one pixel the nearer
/// (larger d) wins. Points
/// without a ring (ring < 0, or an empty ring map) are kept as single pixels. Throws
/// std::invalid_argument on an empty map, a ring map of another size, or values that are not
/// finite and >= 0.
ScanLines completeScanLines(const SparseDisparity& sparse, const BIParams& params);

/// BI* step 2 (Algorithm 1): clears scan-line pixels that have, both above and below in their
/// column (within the next `search_lines` scan-line pixels; 1 = the paper's next scan line), a
/// pixel with disparity larger by more than max_disp_diff whose image colour is within
/// max_color_diff (strictly less, RGB L1) of the colour at the pixel. `image` is the view's BGR
/// image (CV_8UC3) or grey (CV_8UC1, distance 3 |a - b| so the threshold means the same). Every
/// decision is made on the input state (the pixels are cleared after all are decided), so the
/// result does not depend on scan order. Cleared pixels get disparity 0 and ring -1. Returns the
/// number removed; `removed_pixels` (optional) receives them (x = column, y = row). Throws
/// std::invalid_argument for an image of another size or type.
int removeOccludedPoints(ScanLines& lines, const cv::Mat& image, const BIParams& params,
                         std::vector<cv::Point>* removed_pixels = nullptr);

/// BI* step 2b (not in the paper), after Algorithm 1: the LiDAR sits off the camera (KITTI's 8 cm
/// above and 27 cm behind it), so past a near object's edge it sees background that the object
/// hides from the camera, and that background lands in the image on the object's side of the edge
/// (above the camera, under top edges). Algorithm 1 clears such a pixel only with a similar
/// foreground above and below it. Here, for each two consecutive scan-line pixels p and q of a
/// column where q is nearer by more than max_disp_diff: the edge of q's surface lies, as far as
/// the LiDAR can tell, anywhere between q and the LiDAR's ray to p; carried to q's depth that ray
/// lands in the image a shift s from p's row (towards q's side when it can hide p). p is cleared
/// when s >= the rows from p to q: the edge then hides p at least as likely as not (an edge
/// anywhere in that range, evenly). `lidar_origin` is the LiDAR's origin in this view's camera
/// frame [m] (x right, y down, z forward); `camera` gives fx, fy, cx, cy and fx * baseline for
/// the depths. Returns the number cleared; `removed_pixels` (optional) receives them ordered by
/// column, then row. Cleared pixels get disparity 0 and ring -1. Does nothing when
/// params.remove_parallax_hidden is false. Throws std::invalid_argument for an invalid camera or
/// a non-finite origin.
int removeParallaxHidden(ScanLines& lines, const StereoCamera& camera,
                         const Eigen::Vector3d& lidar_origin, const BIParams& params,
                         std::vector<cv::Point>* removed_pixels = nullptr);

/// BI* step 3 (Eq. 3): linear interpolation in every column between the nearest scan lines above
/// and below, when they are at most max_interp_rows apart. Pixels on a line keep its value;
/// pixels above the top or below the bottom line stay 0.
cv::Mat1f interpolateBetweenScanLines(const ScanLines& lines, const BIParams& params);

/// The whole BI* chain. `removed` (optional) receives the Algorithm 1 count; `lines_out`
/// (optional) the scan lines after Algorithm 1, i.e. the lines Eq. 3 interpolated (the input of
/// computeScanLineBounds); `removed_pixels` (optional) the pixels Algorithm 1 cleared.
cv::Mat1f upsampleBI(const SparseDisparity& sparse, const cv::Mat& image, const BIParams& params,
                     int* removed = nullptr, ScanLines* lines_out = nullptr,
                     std::vector<cv::Point>* removed_pixels = nullptr);

/// BF*: bilateral up-sampling of the sparse disparity (Premebida et al. 2016; no occlusion
/// handling, as in the paper's comparison). For every pixel p, over the LiDAR points q of the
/// (2 radius + 1)^2 window: ref = the largest disparity (the nearest point), w_q =
/// exp(-|p - q|^2 / (2 sigma_space^2)) * exp(-(ref - d_q)^2 / (2 sigma_range^2)), D(p) = sum w_q
/// d_q / sum w_q (a constant neighbourhood comes back exactly). Every pixel is filtered, LiDAR
/// pixels included; pixels with fewer than min_support points in the window stay 0. Rows run in
/// parallel with OpenMP on large maps.
cv::Mat1f upsampleBF(const SparseDisparity& sparse, const BFParams& params);

/// Per-pixel search bounds from the scan lines above and below each pixel (paper Sec. III-D):
/// d_up / d_down are the nearest line pixels strictly above / below in the column (a pixel on a
/// line uses the lines around it); lo/hi = min/max(d_up, d_down) -/+ margin; range =
/// |d_up - d_down|. Pixels without a line both above and below get lo = hi = range = 0 (meaning
/// "unbounded"); a pixel is bounded exactly when hi > 0 (lo may be <= 0). No row limit applies.
/// Throws std::invalid_argument for an empty map or a negative / non-finite margin.
struct ScanLineBounds {
  cv::Mat1f lo, hi;  ///< [px]
  cv::Mat1f range;   ///< Delta_d_max for plane refinement [px]
};
ScanLineBounds computeScanLineBounds(const ScanLines& lines, double margin_px);

}  // namespace lidar_stereo_fusion
