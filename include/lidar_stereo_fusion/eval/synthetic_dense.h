// The dense-LiDAR protocol on the synthetic street (sim/synthetic_frame.h), where the exact depth
// is known: the full 64-ring sweep of a frame fed to every method, each scored three times,
// against
//   syn_lidar: a reference made the way KITTI's is, of LiDAR returns: the sweeps of the frames
//     around it cast from their exact poses, projected into the frame's left camera, the nearest
//     point winning a pixel, each return widened over its beam's footprint,
//   syn_exact: the exact depth at the same pixels (where the surface is not sky), and
//   syn_image: the exact depth at every pixel with a surface, above the LiDAR's view too.
// syn_exact and syn_lidar score the same outputs at the same pixels, so the difference between
// them is what building the reference from LiDAR returns does to a method's score
// (doc/accuracy.md, issue 31). No data files are read. ROS-free.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {

/// What the synthetic dense protocol renders and how its LiDAR-made reference is built.
struct SyntheticDenseParams {
  std::vector<uint64_t> seeds{1, 2, 3};  ///< street layouts (SyntheticParams::seed), one frame each
  int frame = 5;                         ///< the scored frame's index
  int half_span = 5;  ///< the reference's sweeps: frames frame - half_span .. frame + half_span
  /// Columns each return covers on either side of its pixel: a beam's footprint across the scan.
  /// A Velodyne beam diverges by about 3 mrad (the VLS-128's manual: 3.0 x 1.5 mrad), 2.2 px at
  /// KITTI's focal length, so a return may come from a foreground up to about a pixel beside its
  /// centre. 0: point samples.
  int footprint_px = 1;
  /// Throws std::invalid_argument naming the first impossible value (no seed, frame - half_span
  /// < 0, half_span or footprint_px < 0).
  void validate() const;
};

/// The LiDAR-made reference of frame `target` of `scene` (rendered with `params`): depth [m] in
/// its left camera, 0 where no return lands. Every sweep of the frames target - half_span ..
/// target + half_span (sim::simulateSweep from the frame's exact pose, params' noise off) is
/// projected (pixel i covers [i - 0.5, i + 0.5)), each return also onto the footprint_px columns
/// either side; the nearest depth wins a pixel.
cv::Mat1f syntheticLidarReference(const sim::Scene& scene, const sim::SyntheticParams& params,
                                  int target, int half_span, int footprint_px);

/// Runs the protocol's wanted layouts (syntheticLayoutNames(): syn_exact, syn_lidar, syn_image)
/// with every wanted method of `options` (pms and "lidar_bi else pms" only when
/// options.kitti_pms); items are the seeds. Methods run once per seed and are scored against
/// every wanted reference.
std::vector<LayoutScores<DepthMetrics>> runSyntheticDenseProtocol(
    const AccuracyOptions& options, const SyntheticDenseParams& params = {});

}  // namespace lidar_stereo_fusion
