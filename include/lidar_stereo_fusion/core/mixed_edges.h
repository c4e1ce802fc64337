// Stage 3, after the output median (not in the paper): pixels that mix a nearer surface's colour
// into a farther one's at a depth edge take the nearer depth.
//
// A pixel on the boundary of a foreground object sees both surfaces: its colour lies between
// theirs. The matcher often gives a pixel that is mostly foreground the background's plane: on the
// synthetic street, where the depth is exact at every pixel centre, 9 of 10 of the pixels this
// step sets come nearer that depth. So a pixel p beside a nearer neighbour q (4-neighbours, depth
// ratio >= kMixedEdgeMinRatio) whose colour, projected on the line from the colour of the pixel p'
// on its far side (p's surface: within kMixedEdgeSameSurface) to q's colour, lies at least
// `min_fraction` of the way to q's takes q's disparity. A lower fraction takes in pixels that are
// mostly background: Middlebury's ground truth (camera-made) puts them on the far surface, while
// references made of LiDAR returns (the nearest return of a pixel wins) put them on the near one;
// 0.75 leaves Middlebury as it was. Measured on every protocol: doc/accuracy.md (mixed edge
// pixels).
#pragma once

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// q's depth at most this fraction of p's (disparity ratio d_q / d_p >= this): a depth edge, not a
/// slanted surface (a road 1 px apart differs by under 1 %); 1.15-1.6 give the same results.
constexpr float kMixedEdgeMinRatio = 1.3f;
/// p' continues p's surface: its disparity at most this factor above p's.
constexpr float kMixedEdgeSameSurface = 1.1f;

struct MixedEdgeParams {
  /// How far p's colour lies from p' to q's colour (0..1) for p to take q's disparity (0 = off).
  float min_fraction = 0.75f;
  /// Smallest RGB L1 difference between p' and q (grey images: 3 |a - b|): below it the colours
  /// cannot tell the surfaces apart.
  float min_contrast = 60.f;
};

/// Sets every mixed edge pixel of `disparity` to its nearest qualifying neighbour's disparity,
/// decided on the input (the result does not depend on the scan order), and returns how many it
/// set. Empty pixels, the image border's pixels and the LiDAR's points that the disparity agrees
/// with within `tolerance` [px] (isMeasuredPoint(sparse, lines), as medianKeepingMeasured keeps
/// them; `sparse` and `lines` may both be empty: none) stay. `image` is 8-bit BGR or grey of the
/// disparity's size. `threads`: strips of rows on the core's pool (patchmatch/parallel.h), the
/// same result for any count. Throws std::invalid_argument for sizes or types that differ, or
/// parameters out of range (fraction in [0, 1], contrast >= 0, tolerance >= 0, all finite).
int nearerAtMixedEdges(cv::Mat1f& disparity, const cv::Mat& image, const cv::Mat1f& sparse,
                       const cv::Mat1f& lines, float tolerance, const MixedEdgeParams& params,
                       int threads = 1);

}  // namespace lidar_stereo_fusion
