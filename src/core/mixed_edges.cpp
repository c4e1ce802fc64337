// Stage 3, after the output median: mixed edge pixels to the nearer surface (mixed_edges.h).
#include "lidar_stereo_fusion/core/mixed_edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "lidar_stereo_fusion/core/output_median.h"
#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {

namespace {

/// The colour of pixel (x, y) as three floats (a grey value three times: the L1 distance is then
/// 3 |a - b|, as Algorithm 1 counts it).
inline void colourAt(const cv::Mat& image, int y, int x, float c[3]) {
  if (image.type() == CV_8UC3) {
    const cv::Vec3b& v = image.at<cv::Vec3b>(y, x);
    for (int k = 0; k < 3; ++k) c[k] = v[k];
  } else {
    c[0] = c[1] = c[2] = image.at<uchar>(y, x);
  }
}

/// Whether p's colour lies at least min_fraction of the way from p' (far side) to q (nearer), on
/// the line between their colours, with enough contrast between them.
bool mixesIn(const cv::Mat& image, int y, int x, int dy, int dx, const MixedEdgeParams& params) {
  float p[3], q[3], far[3];
  colourAt(image, y, x, p);
  colourAt(image, y + dy, x + dx, q);
  colourAt(image, y - dy, x - dx, far);
  float contrast = 0.f, along = 0.f, length = 0.f;
  for (int k = 0; k < 3; ++k) {
    const float v = q[k] - far[k];
    contrast += std::abs(v);
    along += (p[k] - far[k]) * v;
    length += v * v;
  }
  return contrast > 0.f && contrast >= params.min_contrast && along >= params.min_fraction * length;
}

/// The 4-neighbours q = p + step (p' = p - step).
constexpr int kSteps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};

struct Change {
  int y, x;
  float disparity;
};

}  // namespace

int nearerAtMixedEdges(cv::Mat1f& disparity, const cv::Mat& image, const cv::Mat1f& sparse,
                       const cv::Mat1f& lines, float tolerance, const MixedEdgeParams& params,
                       int threads) {
  if (image.size() != disparity.size() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
    throw std::invalid_argument(
        "nearerAtMixedEdges: the image must be 8-bit BGR or grey of the disparity's size");
  }
  if (sparse.size() != lines.size() || (!sparse.empty() && sparse.size() != disparity.size())) {
    throw std::invalid_argument(
        "nearerAtMixedEdges: the projection and the scan lines must both be empty or of the "
        "disparity's size");
  }
  if (!(params.min_fraction >= 0.f && params.min_fraction <= 1.f) ||
      !(params.min_contrast >= 0.f) || !std::isfinite(params.min_contrast) || !(tolerance >= 0.f) ||
      !std::isfinite(tolerance)) {
    throw std::invalid_argument(
        "nearerAtMixedEdges: min_fraction must lie in [0, 1], min_contrast and the tolerance "
        "must be finite and >= 0");
  }
  // Fixed strips of rows, each with its own list of changes, applied after every strip has
  // decided on the input: the result does not depend on the thread count.
  const int rows = disparity.rows - 2;
  const int strips = rows <= 0 ? 0 : std::min(rows, threads <= 1 ? 1 : 4 * threads);
  std::vector<std::vector<Change>> strip_changes(static_cast<size_t>(std::max(0, strips)));
  patchmatch::parallelFor(strips, threads, [&](int strip) {
    std::vector<Change>& changes = strip_changes[static_cast<size_t>(strip)];
    std::vector<uchar> flags(static_cast<size_t>(disparity.cols) + 8, 0);
    const int y_begin = 1 + static_cast<int>(static_cast<int64_t>(rows) * strip / strips);
    const int y_end = 1 + static_cast<int>(static_cast<int64_t>(rows) * (strip + 1) / strips);
    for (int y = y_begin; y < y_end; ++y) {
      const float* __restrict above = disparity[y - 1];
      const float* __restrict row = disparity[y];
      const float* __restrict below = disparity[y + 1];
      uchar* __restrict flag = flags.data();
      // A pass the compiler vectorises flags the pixels with a much nearer 4-neighbour (a few per
      // cent of an image); the scan below skips 8 unflagged pixels at a time.
      for (int x = 1; x + 1 < disparity.cols; ++x) {
        const float nearest =
            std::max(std::max(above[x], below[x]), std::max(row[x - 1], row[x + 1]));
        flag[x] = static_cast<uchar>((row[x] > 0.f) & (nearest >= kMixedEdgeMinRatio * row[x]));
      }
      for (int x = 1; x + 1 < disparity.cols; ++x) {
        if ((x & 7) == 0) {
          uint64_t block;
          std::memcpy(&block, flag + x, sizeof block);
          if (block == 0) {
            x += 7;
            continue;
          }
        }
        if (!flag[x]) continue;
        const float d = disparity(y, x);
        if (!sparse.empty() && keepsMeasuredPoint(d, sparse(y, x), lines(y, x), tolerance)) {
          continue;  // a LiDAR point the output agrees with
        }
        float nearer = d;
        for (const auto& step : kSteps) {
          const float dq = disparity(y + step[0], x + step[1]);
          const float df = disparity(y - step[0], x - step[1]);
          if (dq > nearer && dq >= kMixedEdgeMinRatio * d && df > 0.f &&
              df <= kMixedEdgeSameSurface * d && mixesIn(image, y, x, step[0], step[1], params)) {
            nearer = dq;
          }
        }
        if (nearer > d) changes.push_back({y, x, nearer});
      }
    }
  });
  int count = 0;
  for (const auto& changes : strip_changes) {
    for (const Change& c : changes) disparity(c.y, c.x) = c.disparity;
    count += static_cast<int>(changes.size());
  }
  return count;
}

}  // namespace lidar_stereo_fusion
