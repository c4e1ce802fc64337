// PatchMatch coarse start (coarse_to_fine.h).
#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

cv::Size coarseSize(const cv::Size& full, int scale) {
  return cv::Size(std::max(2, (full.width + scale - 1) / scale),
                  std::max(1, (full.height + scale - 1) / scale));
}

/// Nearest-neighbour reduction of a float map into `out` (its buffer reused when it has the size;
/// released when `map` is empty), values multiplied by `factor`: pixel (x, y) takes (x scale +
/// scale / 2, y scale + scale / 2), clamped to the map.
void reduceMap(const cv::Mat1f& map, const cv::Size& size, int scale, float factor,
               cv::Mat1f& out) {
  if (map.empty()) {
    out.release();
    return;
  }
  out.create(size);
  const int half = scale / 2;
  // The columns whose source lies inside the map; the others (at most one) take its last column.
  const int inside = map.cols > half ? std::min(size.width, (map.cols - 1 - half) / scale + 1) : 0;
  for (int y = 0; y < size.height; ++y) {
    const float* src = map[std::min(map.rows - 1, y * scale + half)];
    float* dst = out[y];
    if (scale == 2) {  // the usual reduction, in a loop the compiler vectorises
      for (int x = 0; x < inside; ++x) dst[x] = src[2 * x + 1] * factor;
    } else {
      for (int x = 0; x < inside; ++x) dst[x] = src[x * scale + half] * factor;
    }
    for (int x = inside; x < size.width; ++x) dst[x] = src[map.cols - 1] * factor;
  }
}

}  // namespace

void downsampleView(const ViewInput& in, int scale, ViewInput& out) {
  const cv::Size size = coarseSize(in.image.size(), scale);
  cv::resize(in.image, out.image, size, 0, 0, cv::INTER_AREA);
  const float inv = 1.f / static_cast<float>(scale);
  reduceMap(in.prior, size, scale, inv, out.prior);
  reduceMap(in.confidence, size, scale, 1.f, out.confidence);
  reduceMap(in.bounds.lo, size, scale, inv, out.bounds.lo);
  reduceMap(in.bounds.hi, size, scale, inv, out.bounds.hi);
  reduceMap(in.bounds.range, size, scale, inv, out.bounds.range);
}

ViewInput downsampleView(const ViewInput& in, int scale) {
  ViewInput out;
  downsampleView(in, scale, out);
  return out;
}

PatchMatchParams coarseParams(const PatchMatchParams& p) {
  PatchMatchParams c = p;
  const int s = p.coarse_scale;
  c.window_radius =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(p.window_radius) / s)));
  c.window_stride = std::min(c.window_radius, std::max(1, p.window_stride / s));
  c.min_disparity = p.min_disparity / s;
  c.max_disparity = p.max_disparity / s;
  c.min_refine_range = p.min_refine_range / s;
  // No left-right check below full size, but on the finest level that searches (search_scale),
  // whose filled result the levels above up-sample; at lr_max_diff in full-size px.
  c.search_scale = std::max(1, p.search_scale / s);
  c.lr_check = p.lr_check && p.search_scale >= s;
  if (c.lr_check) c.lr_max_diff = p.lr_max_diff / s;
  c.coarse_levels = std::max(1, p.coarse_levels - 1);
  c.coarse_scale = p.coarse_levels > 1 ? s : 1;
  // The levels below search everything, in both views, down to unbounded_scale ...
  c.unbounded_scale = std::max(1, p.unbounded_scale / s);
  c.full_size_unbounded = true;
  c.fine_right_view = true;
  // ... and the sub-pixel step belongs to the finest level that searches: full size, or with
  // search_scale > 1 this level when it is 1 / search_scale (it then ends `live`'s search, which
  // otherwise kept the 1/4 level's precision above the LiDAR: Middlebury lower 2/3 -7 % MAE).
  c.fine_subpixel = p.fine_subpixel && p.search_scale == s;
  return c;
}

std::vector<Plane> upsamplePlanes(const cv::Mat3f& coarse, int scale, const cv::Size& full,
                                  int threads) {
  std::vector<Plane> planes(static_cast<size_t>(full.area()));
  // Coarse pixel i covers full pixels i s .. i s + s - 1: x_c = (x - (s - 1) / 2) / s, so
  // d = s d_c(x_c, y_c) = a x + b y + s c - (a + b) (s - 1) / 2.
  const float s = static_cast<float>(scale);
  parallelRows(full.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const cv::Vec3f* row = coarse[std::min(coarse.rows - 1, y / scale)];
      for (int x = 0; x < full.width; ++x) {
        planes[static_cast<size_t>(y) * full.width + x] =
            upsampledPlane(row[std::min(coarse.cols - 1, x / scale)], s);
      }
    }
  });
  return planes;
}

cv::Mat1b upsampleMask(const cv::Mat1b& coarse, int scale, const cv::Size& full) {
  cv::Mat1b out(full);
  for (int y = 0; y < full.height; ++y) {
    const uchar* row = coarse[std::min(coarse.rows - 1, y / scale)];
    uchar* dst = out[y];
    for (int x = 0; x < full.width; ++x) dst[x] = row[std::min(coarse.cols - 1, x / scale)];
  }
  return out;
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
