// The whole method: projection -> up-sampling -> guided PatchMatch -> depth. ROS-free.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/prior_confidence.h"
#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {

enum class Method {
  kFusedBI,   ///< the paper: BI* prior + guided PatchMatch (default)
  kFusedBF,   ///< BF* prior + guided PatchMatch
  kPlainPMS,  ///< PatchMatch stereo without LiDAR (gamma = 0, no bounds, random init)
  kLidarBI,   ///< BI* up-sampled LiDAR only
  kLidarBF,   ///< BF* up-sampled LiDAR only
};

/// "fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf".
std::string methodName(Method method);
/// Parses the names above; throws std::invalid_argument listing the valid names.
Method parseMethod(const std::string& name);
/// fused_bi or fused_bf: the LiDAR's prior guides PatchMatch (scan-line bounds, confidence).
bool isFused(Method method);

struct FusionParams {
  Method method = Method::kFusedBI;
  ProjectionParams projection;
  BIParams bi;
  BFParams bf;
  PriorConfidenceParams confidence;
  PatchMatchParams patchmatch;
  /// Parameters of the plain-PMS baseline (Bleyer: alpha 0.1, beta 0.9, window 35).
  static PatchMatchParams plainPmsParams(PatchMatchParams base);
  void validate() const;
};

/// Per-stage wall time [ms] and counts of one frame.
struct FrameStats {
  double projection_ms = 0, upsampling_ms = 0, patchmatch_ms = 0, depth_ms = 0, total_ms = 0;
  int points_in_front = 0;     ///< points in the depth range in front of the camera
  int points_projected = 0;    ///< points landing in the left image
  int points_removed = 0;      ///< scan-line pixels removed by Algorithm 1 (left view)
  double prior_coverage = 0;   ///< fraction of pixels with an up-sampled prior
  double output_coverage = 0;  ///< fraction of pixels with an output disparity
  std::vector<PatchMatchStep> patchmatch_steps;  ///< PatchMatch's steps (PatchMatchResult::steps)
};

struct FusionResult {
  SparseDisparity sparse;  ///< stage 1 (left view)
  /// Stage 2 (left view) [px], 0 = empty. For the fused methods with confidence weighting, the
  /// prior PatchMatch used: BI* (or BF*) plus the hole fill (fillPriorHoles) at low confidence.
  cv::Mat1f prior;
  /// Confidence of the prior (left view), in [0, 1] (unitless): 1 on measured scan-line pixels,
  /// lower between scan lines that disagree and where Algorithm 1 removed points, 0 where the
  /// prior is empty. Empty for methods without LiDAR. See PriorConfidenceParams.
  cv::Mat1f confidence;
  cv::Mat1f disparity;  ///< final disparity [px], 0 = no value
  cv::Mat1f depth;      ///< final depth [m], 0 = no value
  FrameStats stats;
};

/// One frame: rectified images (BGR CV_8UC3 or grey), the sweep, and LiDAR -> left optical frame.
struct FusionInput {
  cv::Mat left, right;
  LidarCloud cloud;
  Eigen::Isometry3d T_cam_lidar = Eigen::Isometry3d::Identity();
  StereoCamera camera;
};

/// Stateless apart from reusable scratch buffers; not thread-safe (one object per thread).
class FusionPipeline {
 public:
  explicit FusionPipeline(const FusionParams& params = FusionParams());
  /// Validates and replaces the parameters (throws std::invalid_argument).
  void setParams(const FusionParams& params);
  const FusionParams& params() const { return params_; }

  /// Throws std::invalid_argument on bad input (sizes, types, camera) with a message naming it.
  FusionResult process(const FusionInput& input);

  /// Stages 2-4 from sparse disparities already projected into both views (a pseudo-LiDAR made
  /// from ground truth, or a caller that projects itself). `right_sparse` is used by the fused
  /// methods only (may be empty otherwise). The camera gives the depth conversion; pass any valid
  /// camera of the image size when only the disparity is wanted. The LiDAR's pose is unknown
  /// here, so BI* skips removeParallaxHidden. Same errors as process().
  FusionResult processSparse(const cv::Mat& left, const cv::Mat& right,
                             const SparseDisparity& left_sparse,
                             const SparseDisparity& right_sparse, const StereoCamera& camera);

 private:
  /// `lidar_origin`: the LiDAR's origin in the left camera's frame [m] (nullopt: unknown, then
  /// no removeParallaxHidden).
  FusionResult runStages(const cv::Mat& left, const cv::Mat& right,
                         const SparseDisparity& left_sparse, const SparseDisparity& right_sparse,
                         const StereoCamera& camera,
                         const std::optional<Eigen::Vector3d>& lidar_origin);

  FusionParams params_;
  PatchMatchStereo patchmatch_;
};

}  // namespace lidar_stereo_fusion
