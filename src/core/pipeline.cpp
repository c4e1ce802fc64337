// The whole method, stage by stage: projection -> up-sampling -> guided PatchMatch -> depth.
#include "lidar_stereo_fusion/core/pipeline.h"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <utility>

#include "lidar_stereo_fusion/core/both_views.h"
#include "lidar_stereo_fusion/core/mixed_edges.h"
#include "lidar_stereo_fusion/core/motion_compensation.h"
#include "lidar_stereo_fusion/core/output_median.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"

#include "scan_line_columns.h"

namespace lidar_stereo_fusion {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

bool usesLidar(Method m) { return m != Method::kPlainPMS; }
bool usesPatchMatch(Method m) {
  return m == Method::kFusedBI || m == Method::kFusedBF || m == Method::kPlainPMS;
}
bool usesBF(Method m) { return m == Method::kFusedBF || m == Method::kLidarBF; }

double coverage(const cv::Mat1f& m) {
  if (m.empty()) return 0.0;
  return static_cast<double>(cv::countNonZero(m > 0.f)) / static_cast<double>(m.total());
}

void checkInput(const FusionInput& in) {
  in.camera.validate();
  if (in.left.empty() || in.right.empty())
    throw std::invalid_argument("left or right image is empty");
  if (in.left.size() != in.right.size()) {
    throw std::invalid_argument("left and right images differ in size");
  }
  if (in.left.type() != in.right.type()) {
    throw std::invalid_argument("left and right images differ in type");
  }
  if (in.left.type() != CV_8UC3 && in.left.type() != CV_8UC1) {
    throw std::invalid_argument("images must be 8-bit BGR (CV_8UC3) or grey (CV_8UC1)");
  }
  if (in.left.cols != in.camera.width || in.left.rows != in.camera.height) {
    throw std::invalid_argument("image size " + std::to_string(in.left.cols) + "x" +
                                std::to_string(in.left.rows) + " differs from the camera's " +
                                std::to_string(in.camera.width) + "x" +
                                std::to_string(in.camera.height));
  }
}

/// Stage 2 of one view: scan lines after Algorithm 1, the prior of the chosen up-sampler, bounds.
struct ViewPrior {
  ScanLines lines;
  cv::Mat1f prior;
  cv::Mat1f confidence;
  ScanLineBounds bounds;
  int removed = 0;

  ViewInput input(const cv::Mat& image) const {
    return ViewInput{image, prior, bounds, confidence};
  }
};

ViewPrior upsampleView(const SparseDisparity& sparse, const cv::Mat& image,
                       const FusionParams& params, const StereoCamera& camera,
                       const std::optional<Eigen::Vector3d>& lidar_origin) {
  ViewPrior v;
  std::vector<cv::Point> removed;
  // upsampleBI's steps, with one column index for Algorithm 1, Eq. 3, the bounds and the
  // confidence, and BI*'s three maps in one pass.
  v.lines = completeScanLines(sparse, params.bi);
  ColumnIndex index = removeOccludedPointsIndexed(v.lines, image, params.bi, removed);
  // The pixels step 2b clears are left to the images: LiDAR-only BI* keeps them (without images
  // Eq. 3 would blend the two lines there; ring hold-out 32 rings 1102 -> 1113 mm).
  if (lidar_origin && isFused(params.method)) {
    removeParallaxHiddenIndexed(v.lines, index, camera, *lidar_origin, params.bi, removed);
  }
  v.removed = static_cast<int>(removed.size());
  const IntervalConfidence model(params.confidence, v.lines.disparity.size(), removed);
  IntervalMaps maps;
  maps.bounds = &v.bounds;
  maps.confidence = &v.confidence;
  const double margin = params.patchmatch.bound_margin;
  if (usesBF(params.method)) {  // BF*'s prior; the bounds and its confidence from the lines
    v.prior = upsampleBF(sparse, params.bf);
    scanLineIntervals(index, v.lines.disparity, 0, margin, &model, maps, &v.prior);
  } else {
    maps.prior = &v.prior;
    scanLineIntervals(index, v.lines.disparity, params.bi.max_interp_rows, margin, &model, maps);
  }
  if (isFused(params.method) && params.patchmatch.confidence_weighting) {
    fillPriorHoles(v.prior, v.confidence, params.confidence);
  }
  return v;
}

/// Threads for the two views' per-view stages (projection, up-sampling): side by side unless the
/// user asked for one thread.
int viewThreads(const FusionParams& p) { return p.patchmatch.num_threads != 1 ? 2 : 1; }

}  // namespace

std::string methodName(Method method) {
  switch (method) {
    case Method::kFusedBI:
      return "fused_bi";
    case Method::kFusedBF:
      return "fused_bf";
    case Method::kPlainPMS:
      return "pms";
    case Method::kLidarBI:
      return "lidar_bi";
    case Method::kLidarBF:
      return "lidar_bf";
  }
  return "unknown";
}

bool isFused(Method method) { return method == Method::kFusedBI || method == Method::kFusedBF; }

Method parseMethod(const std::string& name) {
  for (Method m : {Method::kFusedBI, Method::kFusedBF, Method::kPlainPMS, Method::kLidarBI,
                   Method::kLidarBF}) {
    if (methodName(m) == name) return m;
  }
  throw std::invalid_argument("unknown method '" + name +
                              "' (valid: fused_bi, fused_bf, pms, lidar_bi, lidar_bf)");
}

PatchMatchParams FusionParams::plainPmsParams(PatchMatchParams base) {
  // Bleyer et al. 2011: (1 - 0.9) colour + 0.9 gradient, a 35x35 window (sampled every 3rd pixel
  // for speed), both views swept every iteration; no LiDAR term, no bounds, random initialisation.
  // (An 11x11 window was worse: KITTI hold-out 55.7 % against 42.9 % of pixels off by > 3 px,
  // Middlebury cones 14.4 % against 10.1 % bad-2.)
  base.alpha = 0.1;
  base.beta = 0.9;
  base.gamma = 0.0;
  base.window_radius = 17;
  base.window_stride = 3;
  base.window_dyadic = false;
  base.window_round = false;
  base.median_radius = 17;
  base.output_median = 0;  // not Bleyer's
  base.mixed_edge_fraction = 0.0;
  base.iterations = 3;  // Bleyer's
  base.right_iterations = -1;
  base.init_from_prior = false;
  base.use_lidar_bounds = false;
  base.coarse_scale = 1;  // Bleyer: the search runs at full size, every pixel searched
  base.search_scale = 1;  // (a preset's coarse-only search has no level here)
  base.unbounded_scale = 1;
  return base;
}

void FusionParams::validate() const {
  projection.validate();
  bi.validate();
  bf.validate();
  confidence.validate();
  patchmatch.validate();
}

FusionPipeline::FusionPipeline(const FusionParams& params) {
  patchmatch_.setPlanesOutput(false);  // the result is the disparity
  setParams(params);
}

void FusionPipeline::setParams(const FusionParams& params) {
  params.validate();
  params_ = params;
  patchmatch_.setParams(params.method == Method::kPlainPMS
                            ? FusionParams::plainPmsParams(params.patchmatch)
                            : params.patchmatch);
}

FusionResult FusionPipeline::process(const FusionInput& input) {
  checkInput(input);
  const auto start = Clock::now();
  const Method method = params_.method;

  // Stage 1: projection (left always, for stats and inspection; right only for fused methods,
  // beside the left).
  const auto t = Clock::now();
  SparseDisparity left_sparse, right_sparse;
  // Points hidden beside near objects from the camera (projection.remove_hidden_beside).
  LidarCloud visible;
  const LidarCloud* cloud = &input.cloud;
  if (params_.projection.remove_hidden_beside && usesLidar(method)) {
    visible = input.cloud;
    removePointsHiddenBeside(visible, input.T_cam_lidar, input.camera);
    cloud = &visible;
  }
  const auto project = [&](View view, SparseDisparity& out) {
    out = projectCloud(*cloud, input.T_cam_lidar, input.camera, params_.projection, view);
  };
  if (isFused(method)) {
    bothViews(
        viewThreads(params_), [&] { project(View::kLeft, left_sparse); },
        [&] { project(View::kRight, right_sparse); });
  } else {
    project(View::kLeft, left_sparse);
  }
  if (usesLidar(method) && left_sparse.points_in_image == 0) {
    const std::size_t points = input.cloud.size();
    if (points > 0 && static_cast<std::size_t>(left_sparse.points_not_finite) == points) {
      throw std::invalid_argument("none of the " + std::to_string(points) +
                                  " LiDAR points is finite (x, y or z NaN / inf): check the sweep");
    }
    throw std::invalid_argument(
        "no LiDAR points land in the image (" + std::to_string(points) + " points, " +
        std::to_string(left_sparse.points_not_finite) + " of them not finite, " +
        std::to_string(left_sparse.points_in_front) +
        " in front of the camera): check the cloud and the LiDAR->camera transform");
  }
  const double projection_ms = msSince(t);
  FusionResult result = runStages(input.left, input.right, left_sparse, right_sparse, input.camera,
                                  input.T_cam_lidar.translation());
  result.stats.projection_ms = projection_ms;
  result.stats.total_ms = msSince(start);
  return result;
}

FusionResult FusionPipeline::processSparse(const cv::Mat& left, const cv::Mat& right,
                                           const SparseDisparity& left_sparse,
                                           const SparseDisparity& right_sparse,
                                           const StereoCamera& camera) {
  checkInput(FusionInput{left, right, LidarCloud(), Eigen::Isometry3d::Identity(), camera});
  const cv::Size size = left.size();
  if (usesLidar(params_.method) && left_sparse.disparity.size() != size) {
    throw std::invalid_argument("left sparse disparity size differs from the image size");
  }
  if (isFused(params_.method) && right_sparse.disparity.size() != size) {
    throw std::invalid_argument("right sparse disparity size differs from the image size");
  }
  const auto start = Clock::now();
  FusionResult result = runStages(left, right, left_sparse, right_sparse, camera, std::nullopt);
  result.stats.total_ms = msSince(start);
  return result;
}

FusionResult FusionPipeline::runStages(const cv::Mat& left_image, const cv::Mat& right_image,
                                       const SparseDisparity& left_sparse,
                                       const SparseDisparity& right_sparse,
                                       const StereoCamera& camera,
                                       const std::optional<Eigen::Vector3d>& lidar_origin) {
  const Method method = params_.method;
  FusionResult result;
  FrameStats& stats = result.stats;
  result.sparse = left_sparse;
  stats.points_in_front = left_sparse.points_in_front;
  stats.points_projected = left_sparse.points_in_image;
  const bool fused = isFused(method);

  // Stage 2: up-sampling (and the prior's confidence).
  auto t = Clock::now();
  ViewPrior left_prior, right_prior;
  const auto left_view = [&] {
    if (!usesLidar(method)) return;
    left_prior = upsampleView(left_sparse, left_image, params_, camera, lidar_origin);
    stats.points_removed = left_prior.removed;
    result.prior = left_prior.prior;
    result.confidence = left_prior.confidence;
    stats.prior_coverage = coverage(result.prior);
  };
  if (fused) {  // the right view's prior is made beside the left's
    bothViews(viewThreads(params_), left_view, [&] {
      // The right camera sits baseline to the left camera's right: the same origin,
      // baseline nearer its x = 0.
      std::optional<Eigen::Vector3d> right_origin = lidar_origin;
      if (right_origin) right_origin->x() -= camera.baseline;
      right_prior = upsampleView(right_sparse, right_image, params_, camera, right_origin);
    });
  } else {
    left_view();
  }
  stats.upsampling_ms = msSince(t);

  // Stage 3: PatchMatch.
  t = Clock::now();
  if (usesPatchMatch(method)) {
    ViewInput left{left_image, cv::Mat1f(), ScanLineBounds(), cv::Mat1f()};
    ViewInput right{right_image, cv::Mat1f(), ScanLineBounds(), cv::Mat1f()};
    if (fused) {
      left = left_prior.input(left_image);
      right = right_prior.input(right_image);
    }
    PatchMatchResult matched = patchmatch_.compute(left, right);
    result.disparity = matched.disparity;
    if (fused && params_.patchmatch.output_median > 0) {
      // The median removes speckles, not the LiDAR's points that the matcher confirms.
      result.disparity = medianKeepingMeasured(
          result.disparity, params_.patchmatch.output_median, left_sparse.disparity,
          left_prior.lines.disparity, static_cast<float>(params_.confidence.edge_tolerance));
    }
    if (fused && params_.patchmatch.mixed_edge_fraction > 0.0) {
      // Boundary pixels that show the nearer surface too take its depth; the LiDAR's points stay.
      const MixedEdgeParams mixed{static_cast<float>(params_.patchmatch.mixed_edge_fraction),
                                  static_cast<float>(params_.patchmatch.mixed_edge_contrast)};
      nearerAtMixedEdges(result.disparity, left_image, left_sparse.disparity,
                         left_prior.lines.disparity,
                         static_cast<float>(params_.confidence.edge_tolerance), mixed,
                         patchmatch::threadCount(params_.patchmatch));
    }
    stats.patchmatch_steps = std::move(matched.steps);
  } else {
    result.disparity = result.prior.clone();
  }
  stats.patchmatch_ms = msSince(t);

  // Stage 4: depth.
  t = Clock::now();
  result.depth = disparityToDepth(result.disparity, camera, params_.projection.max_depth);
  stats.output_coverage = coverage(result.disparity);
  stats.depth_ms = msSince(t);
  return result;
}

}  // namespace lidar_stereo_fusion
