// What the accuracy protocols share (eval/accuracy_protocols.h, eval/accuracy_dense.h): scoring
// with the devkit fill per region, the rows that run, their accumulation, and every method on one
// KITTI case (a fed cloud and a reference depth). Private to src/eval.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace accuracy_detail {

extern const char* const kLidarElsePms;
extern const char* const kNearest;
extern const char* const kIpBasic;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t);

/// Fraction of the reference pixels (> 0) where `estimate` has a value (> 0 and finite).
double rawCoverage(const cv::Mat1f& estimate, const cv::Mat1f& reference);

/// Scores of every region: the estimate is filled like the devkit first.
RegionScores<DisparityMetrics> scoreRegions(const cv::Mat1f& disparity, const cv::Mat1f& reference,
                                            const RegionMasks& masks);
RegionScores<DepthMetrics> scoreRegions(const cv::Mat1f& depth, const cv::Mat1f& reference,
                                        const RegionMasks& masks, const StereoCamera& camera);

/// IP-Basic on a sparse disparity map [px]: to depth with `camera` (z = fx B / d), ipBasicFill,
/// back to disparity.
cv::Mat1f ipBasicOnDisparity(const cv::Mat1f& disparity, const StereoCamera& camera,
                             const IpBasicParams& params);

/// options.save_dir's files of one case (AccuracyOptions::save_dir); nothing when it is empty.
/// `item` with spaces turned into '-'. Throws std::runtime_error naming a file it cannot write.
void saveCase(const AccuracyOptions& options, const std::string& layout, const std::string& item,
              const std::vector<std::pair<std::string, cv::Mat1f>>& outputs,
              const cv::Mat1f& reference, const cv::Mat& left);

bool wantedRow(const AccuracyOptions& options, const std::string& name);
bool wantedLayout(const AccuracyOptions& options, const std::string& name);

/// The pipeline rows that run: name -> parameters (lidar_bi and pms also when only "lidar_bi else
/// pms" needs them; pms only `with_pms`).
std::vector<std::pair<std::string, FusionParams>> pipelineRows(const AccuracyOptions& options,
                                                               bool with_pms);

/// Accumulates the rows of one layout in table order.
template <typename Metrics>
class LayoutAccumulator {
 public:
  void add(const std::string& method, const RegionScores<Metrics>& scores, double raw_coverage,
           double seconds, const EdgeSides& edge_sides) {
    MethodScores<Metrics>& m = rows_[method];
    m.edge_sides += edge_sides;
    m.name = method;
    m.per_item.push_back(scores);
    m.raw_coverage += raw_coverage;
    m.seconds += seconds;
  }
  /// Means over items, rows in accuracyMethodNames() order.
  std::vector<MethodScores<Metrics>> finish() const {
    std::vector<MethodScores<Metrics>> out;
    for (const std::string& name : accuracyMethodNames()) {
      auto it = rows_.find(name);
      if (it == rows_.end()) continue;
      MethodScores<Metrics> m = it->second;
      for (int r = 0; r < kRegionCount; ++r) {
        std::vector<Metrics> items;
        for (const auto& scores : m.per_item) items.push_back(scores[r]);
        m.mean[r] = averageMetrics(items);
      }
      if (!m.per_item.empty()) m.raw_coverage /= m.per_item.size();
      out.push_back(std::move(m));
    }
    return out;
  }

 private:
  std::map<std::string, MethodScores<Metrics>> rows_;
};

/// Distinct ring values of a cloud: the rings a layout feeds (fed_rings).
int distinctRings(const LidarCloud& cloud);

/// A KITTI sweep as the protocols feed it (options.sweep_order; eval/sweep_order.h).
struct FedSweep {
  LidarCloud cloud;
  int rings = 0;     ///< distinct rings of the fed cloud (recovered ones with the order lost)
  std::string note;  ///< for the layout's description: "" as recorded, else how it was fed
};
/// `cloud` (rings from the sweep order) in options.sweep_order, rings recovered for KITTI's
/// HDL-64E (num_rings 64, the node's default); kShuffled with seed 7.
FedSweep fedSweep(const LidarCloud& cloud, const AccuracyOptions& options,
                  const kitti::Calibration& calib);

/// One KITTI case: a frame's images, the cloud fed to every method, the reference depth.
struct DepthCase {
  const kitti::FrameData& frame;
  const LidarCloud& fed;
  const cv::Mat1f& reference;  ///< [m], 0 = no reference
  const kitti::Calibration& calib;
  std::string layout = {}, item = {};  ///< saveCase's names (scoreDepthCase's one target)
};

/// The pms result of a frame, shared by its layouts (pms uses no LiDAR).
struct PmsRun {
  cv::Mat1f depth;
  double seconds = 0;
};

/// Runs every wanted row on `c` (the pipeline rows, "lidar_bi else pms", nearest and ip_basic on
/// the fed cloud's left projection) and adds their scores per region (regions from the fed
/// projection, depth bands from the reference) to `acc`. `pms` is filled on the frame's first
/// case and reused after.
void scoreDepthCase(const DepthCase& c, const AccuracyOptions& options,
                    const std::vector<std::pair<std::string, FusionParams>>& rows, PmsRun& pms,
                    LayoutAccumulator<DepthMetrics>& acc);

/// A reference depth [m] and the accumulator of the layout it scores.
struct DepthTarget {
  const cv::Mat1f& reference;
  LayoutAccumulator<DepthMetrics>& acc;
  std::string layout = {};  ///< saveCase's name of the layout
};

/// scoreDepthCase against several references of the same frame and fed cloud: every row runs
/// once and is scored against each (c.reference is not read).
void scoreDepthCaseAgainst(const DepthCase& c, const std::vector<DepthTarget>& targets,
                           const AccuracyOptions& options,
                           const std::vector<std::pair<std::string, FusionParams>>& rows,
                           PmsRun& pms);

}  // namespace accuracy_detail
}  // namespace lidar_stereo_fusion
