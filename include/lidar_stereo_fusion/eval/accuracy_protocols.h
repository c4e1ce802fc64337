// The accuracy protocols: every method on every protocol, with per-region figures. ROS-free.
//
// Protocols (data in ../shared/data, read in place):
//  * Middlebury 2003 cones + teddy (quarter size). The pseudo-LiDAR is the ground-truth disparity
//    sampled on rows (sampleRowsAsScanLines): "mb64" 64 rows, "mb16" 16 rows, "mb42low" 42 rows
//    over the lower 2/3 only (first row = floor(H / 3)). The right view is shiftToRightView. Scored
//    with evaluateDisparity over every ground-truth pixel [px]; mean of the two scenes.
//  * KITTI raw drive 0009 ring hold-out (makeRingHoldout): "ring32" feeds rings with ring % 2 == 0,
//    "ring16" rings with ring % 4 == 0; all other rings' points are the reference depth. Scored
//    with evaluateDepth; mean over frames (averageMetrics).
//  * KITTI raw drive 0009 dense LiDAR (eval/accuracy_dense.h): "dense" feeds frame 20's full sweep
//    and scores against the depth accumulated from sweeps 15-25 (eval/kitti_accumulated.h).
//
// Scoring rule for every method: empty pixels are first filled by fillLikeDevkit (the KITTI
// devkit's interpolateBackground), as the KITTI benchmark does; "raw coverage" reports the fraction
// of reference pixels the method covered before that fill.
//
// Methods (rows): "fused" (FusionParams() defaults), "paper" (the preset, when given), "lidar_bi",
// "lidar_bf", "pms" (all through FusionPipeline), "lidar_bi else pms" (lidar_bi where it has a
// value, pms elsewhere), "nearest" (every pixel takes the disparity of the nearest fed LiDAR
// pixel, exact 2-D Euclidean distance; needs no fill) and "ip_basic" (core/ip_basic.h on the fed
// sparse depth; on Middlebury the disparity is turned into depth and back with the protocol's
// camera, fx B = 100 px m, so that the quarter-size disparities 5-64 px are 1.6-20 m).
//
// Regions (each scored separately over the reference pixels inside it), from the fed sparse
// disparity of the left view:
//  * "above"  : pixels above the topmost fed pixel of their column (a column without any fed
//               pixel is entirely "above": no LiDAR looks at it);
//  * "above, both views": "above" pixels whose reference match x - d lies inside the right image
//               (set by RegionMasks::setInBothViews from the reference disparity): only the
//               images decide there, and both show the pixel. The rest of "above" is the band at
//               the left border that the right image does not see, where a method can only
//               guess (hole filling), and which weighs differently from scene to scene;
//  * "inside" : every other pixel (on or below the topmost fed pixel of the column);
//  * "edge"   : inside pixels strictly between two scan lines of their column (not on a line)
//               whose lines differ by more than 3 px: the scan lines are those of BI* after
//               completion and Algorithm 1 with the default BIParams (completeScanLines +
//               removeOccludedPoints), and the difference is computeScanLineBounds(lines, 0).range
//               = |d_up - d_down| [px];
//  * "elsewhere": inside and not edge.
// Depth bands (KITTI protocols; empty on Middlebury), by the reference depth z [m]: "< 10 m"
// (z < 10), "10-30 m" (10 <= z < 30), ">= 30 m" (z >= 30); with them "rows < 150" (image rows
// y < kTopRowsEnd): the rows of a KITTI image above and around the HDL-64E's top beam, the last
// column of issue 31's table on KITTI's ground truth.
#pragma once

#include <array>
#include <iosfwd>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/ip_basic.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/eval/edge_sides.h"
#include "lidar_stereo_fusion/eval/sweep_order.h"

namespace lidar_stereo_fusion {

enum class Region {
  kAll,
  kAbove,
  kInside,
  kEdge,
  kElsewhere,
  kNear,
  kMid,
  kFar,
  kAboveBothViews,
  kTopRows
};
constexpr int kRegionCount = 10;
/// The depth bands' limits [m] (kNear: z < kNearBandMax, kFar: z >= kFarBandMin).
constexpr double kNearBandMax = 10.0;
constexpr double kFarBandMin = 30.0;
/// Region::kTopRows: the image rows y < kTopRowsEnd.
constexpr int kTopRowsEnd = 150;
/// "all", "above", "inside", "edge", "elsewhere", "< 10 m", "10-30 m", ">= 30 m", "above, both
/// views", "rows < 150".
std::string regionName(Region region);

/// Region masks of one image (CV_8U, 255 inside the region); see the file comment.
struct RegionMasks {
  cv::Mat1b above, inside, edge, elsewhere;
  cv::Mat1b near, mid, far;                    ///< depth bands; all 0 until setDepthBands
  cv::Mat1b top_rows;                          ///< rows < kTopRowsEnd; all 0 until setDepthBands
  cv::Mat1b above_both_views;                  ///< all 0 until setInBothViews
  const cv::Mat1b& mask(Region region) const;  ///< empty Mat for kAll
  /// Sets the depth bands from a reference depth map [m] (0 / NaN = no reference) of the masks'
  /// size, and top_rows. Throws std::invalid_argument on a size mismatch.
  void setDepthBands(const cv::Mat1f& reference_depth);
  /// Sets above_both_views from the left view's reference disparity [px] (0 / NaN = none) of the
  /// masks' size: the "above" pixels (x, y) with x - d >= 0. Throws std::invalid_argument on a
  /// size mismatch.
  void setInBothViews(const cv::Mat1f& reference_disparity);
};

/// Masks from the fed left-view sparse disparity and the left image (BGR or grey, same size); the
/// depth bands all 0.
/// `edge_range_px` is the scan-line disagreement [px] above which a pixel is "edge" (3 px).
/// Throws std::invalid_argument on an empty map or a size mismatch.
RegionMasks computeRegionMasks(const SparseDisparity& fed, const cv::Mat& image,
                               double edge_range_px = 3.0);

/// Every pixel takes the disparity [px] of the nearest pixel of `fed` with a value (> 0), by exact
/// 2-D Euclidean distance (Felzenszwalb-Huttenlocher distance transform with arg-min; ties go to
/// the pixel found first: the upper one in a column, then the left one). All zero when `fed` has no
/// value. Throws std::invalid_argument on an empty map.
cv::Mat1f nearestFill(const cv::Mat1f& fed);

/// `primary` where it has a value (> 0 and finite), `fallback` elsewhere (0 when neither has).
/// Throws std::invalid_argument on a size mismatch.
cv::Mat1f combineMaps(const cv::Mat1f& primary, const cv::Mat1f& fallback);

/// Scores of one method in every region; index with static_cast<int>(Region).
template <typename Metrics>
using RegionScores = std::array<Metrics, kRegionCount>;

template <typename Metrics>
struct MethodScores {
  std::string name;                             ///< "fused", "lidar_bi", ...
  std::vector<RegionScores<Metrics>> per_item;  ///< one per scene / frame (LayoutScores::items)
  RegionScores<Metrics> mean;                   ///< averageMetrics over the items, per region
  double raw_coverage = 0;  ///< mean fraction of reference pixels covered before the fill
  /// Wall time of the method over all items [s]. pms uses no LiDAR: it runs once per scene /
  /// frame and that run's time is reported in every layout.
  double seconds = 0;
  /// Where the reference's surface lies at the method's own depth edges, summed over the items
  /// (eval/edge_sides.h).
  EdgeSides edge_sides;
};

/// One layout (a pseudo-LiDAR of a given density, a ring subset) of one protocol.
template <typename Metrics>
struct LayoutScores {
  std::string name;                ///< one of accuracyLayoutNames()
  std::string description;         ///< one line for the table title
  std::vector<std::string> items;  ///< scene or frame names
  std::vector<MethodScores<Metrics>> methods;
  std::vector<int> fed_rings;  ///< distinct rings fed, per item
  std::vector<int> fed_rows;   ///< Middlebury: the image rows of the pseudo-LiDAR (first item)
  /// The method's scores, or nullptr when it did not run.
  const MethodScores<Metrics>* find(const std::string& method) const {
    for (const MethodScores<Metrics>& m : methods) {
      if (m.name == method) return &m;
    }
    return nullptr;
  }
};

/// What to run.
struct AccuracyOptions {
  std::string data_dir;               ///< the folder of ../shared/data
  FusionParams fused;                 ///< the "fused" row (and the base of lidar_*, pms)
  std::optional<FusionParams> paper;  ///< the "paper" row; absent: the row is skipped
  IpBasicParams ip_basic;             ///< the "ip_basic" row
  /// Method rows to run (names as above); empty = all. "lidar_bi else pms" needs both parts.
  std::set<std::string> methods;
  std::set<std::string> layouts;  ///< layout names to run; empty = all
  int kitti_frames = 0;           ///< the first N frames; 0 = all
  bool kitti_pms = true;  ///< false: skip pms and "lidar_bi else pms" on KITTI (ring and dense)
  /// KITTI (ring hold-out and dense): the fed sweep as recorded, or with its order lost and its
  /// rings recovered as the node does (eval/sweep_order.h; the hold-out still splits by the
  /// recorded rings, and the reference is unchanged).
  SweepOrder sweep_order = SweepOrder::kRecorded;
  std::ostream* progress = nullptr;  ///< one line per scene / frame when set
  /// When set, every scored case is written there (the folder is created): each method's output
  /// as run, before the devkit fill (<layout>_<item>_<method>.tiff, 32-bit float: disparity [px]
  /// on Middlebury, depth [m] elsewhere), the reference (<layout>_<item>_reference.tiff) and the
  /// left image (<layout>_<item>_left.png); <item> is the scene, the KITTI frame or "seed-N".
  /// A file that cannot be written throws std::runtime_error naming it.
  std::string save_dir;
  /// Throws std::invalid_argument for an unknown method / layout name or kitti_frames < 0.
  void validate() const;
};

/// Creates `dir` (AccuracyOptions::save_dir) with its parents, or finds it there; throws
/// std::runtime_error "cannot create the folder <dir>: <reason>" where it cannot.
void createSaveDir(const std::string& dir);

/// The method row names in table order, and the layout names of each protocol.
std::vector<std::string> accuracyMethodNames();
std::vector<std::string> middleburyLayoutNames();
std::vector<std::string> kittiLayoutNames();
std::vector<std::string> denseLayoutNames();
std::vector<std::string> syntheticLayoutNames();  ///< eval/synthetic_dense.h
/// Every protocol's layout names, in the order above.
std::vector<std::string> accuracyLayoutNames();
/// `names` joined by ", " (the valid names in a message).
std::string joinedNames(const std::vector<std::string>& names);

/// Middlebury pseudo-LiDAR of a layout ("mb64", "mb16", "mb42low") for a ground-truth map [px].
/// Throws std::invalid_argument for an unknown layout.
SparseDisparity middleburyLayout(const cv::Mat1f& ground_truth, const std::string& layout);
/// keep_every of a KITTI layout: ring32 -> 2, ring16 -> 4; throws for an unknown layout.
int kittiKeepEvery(const std::string& layout);

/// Runs the Middlebury protocol (data_dir/middlebury/{cones,teddy}); one entry per layout.
/// Throws std::runtime_error when the data is missing.
std::vector<LayoutScores<DisparityMetrics>> runMiddleburyProtocol(const AccuracyOptions& options);

/// Runs the KITTI ring hold-out (data_dir/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync).
std::vector<LayoutScores<DepthMetrics>> runKittiProtocol(const AccuracyOptions& options);

}  // namespace lidar_stereo_fusion
