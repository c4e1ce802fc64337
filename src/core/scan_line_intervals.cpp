// Stage 2's maps by interval between the scan lines of a column, in one row-major pass: Eq. 3 (BI*
// step 3, paper Sec. III-B), the search bounds (Sec. III-D) and the prior's confidence
// (prior_confidence.h). The declarations and readings are in scan_line_columns.h.
#include <algorithm>
#include <cmath>
#include <vector>

#include "scan_line_columns.h"

namespace lidar_stereo_fusion {

namespace {

/// One column's state while the rows pass: the interval the row is in.
struct ColumnState {
  int line = 0;        ///< the column's next line (index into its entries)
  int up = 0;          ///< row of the line above, when bridged
  int down = -1;       ///< row of the line below, when bridged (Eq. 3 reaches it); -1: not
  float d_up = 0.f;    ///< their disparities [px]
  float d_down = 0.f;  ///<
  float agree = 0.f;   ///< the confidence's agreement of the interval
  float lo = 0.f, hi = 0.f, range = 0.f;  ///< bounds of the interval (0: unbounded)
};

/// lo / hi = min / max of the two lines -/+ margin, range = their difference (upsampling.h).
void setBounds(float d_up, float d_down, double margin_px, float& lo, float& hi, float& range) {
  lo = static_cast<float>(std::min(d_up, d_down) - margin_px);
  hi = static_cast<float>(std::max(d_up, d_down) + margin_px);
  range = std::abs(d_up - d_down);
}

}  // namespace

void scanLineIntervals(const ColumnIndex& index, const cv::Mat1f& lines, int max_interp_rows,
                       double margin_px, const IntervalConfidence* confidence_model,
                       const IntervalMaps& out, const cv::Mat1f* prior_of_confidence) {
  const int rows = lines.rows, cols = lines.cols;
  // The prior the confidence reads (where it has a value, which intervals it bridges): BI*'s own
  // Eq. 3 unless another is given (then Eq. 3 is not written).
  const cv::Mat1f* const other = prior_of_confidence;
  cv::Mat1f* const prior = other ? nullptr : out.prior;
  ScanLineBounds* const bounds = out.bounds;
  cv::Mat1f* const confidence = confidence_model ? out.confidence : nullptr;
  if (prior) prior->create(lines.size());
  if (bounds) {
    bounds->lo.create(lines.size());
    bounds->hi.create(lines.size());
    bounds->range.create(lines.size());
  }
  if (confidence) confidence->create(lines.size());
  std::vector<ColumnState> state(static_cast<size_t>(cols));
  for (int y = 0; y < rows; ++y) {
    const float* on_line = lines[y];
    float* p = prior ? (*prior)[y] : nullptr;
    float* c = confidence ? (*confidence)[y] : nullptr;
    float* lo = bounds ? bounds->lo[y] : nullptr;
    float* hi = bounds ? bounds->hi[y] : nullptr;
    float* range = bounds ? bounds->range[y] : nullptr;
    for (int x = 0; x < cols; ++x) {
      ColumnState& s = state[static_cast<size_t>(x)];
      if (on_line[x] > 0.f) {
        // A line: it keeps its value, is bounded by the lines around it, and starts an interval.
        const ColumnEntry* e = index.column(x);
        const int n = index.size(x);
        const int k = s.line++;  // e[k] is this pixel
        const bool below = k + 1 < n;
        if (p) p[x] = e[k].d;
        if (c) c[x] = !other || (*other)(y, x) > 0.f ? 1.f : 0.f;
        if (bounds) {
          lo[x] = hi[x] = range[x] = 0.f;
          if (k >= 1 && below) setBounds(e[k - 1].d, e[k + 1].d, margin_px, lo[x], hi[x], range[x]);
        }
        s.lo = s.hi = s.range = 0.f;
        s.down = -1;
        if (!below) continue;
        setBounds(e[k].d, e[k + 1].d, margin_px, s.lo, s.hi, s.range);
        // Eq. 3 bridges lines up to max_interp_rows apart; another prior, where it has a value
        // just below the line (adjacent lines have nothing between them).
        const int gap = e[k + 1].y - y;
        if (other ? gap < 2 || !((*other)(y + 1, x) > 0.f) : gap > max_interp_rows) continue;
        s.up = y;
        s.down = e[k + 1].y;
        s.d_up = e[k].d;
        s.d_down = e[k + 1].d;
        s.agree = c && s.down - y >= 2 ? confidence_model->agreement(e, n, k, x) : 0.f;
        continue;
      }
      if (bounds) {
        lo[x] = s.lo;
        hi[x] = s.hi;
        range[x] = s.range;
      }
      if (y >= s.down) {  // not between two bridged lines (or s.down == -1)
        if (p) p[x] = 0.f;
        if (c) c[x] = 0.f;
        continue;
      }
      const int gap = s.down - s.up;
      const float d = other ? (*other)(y, x)
                            : static_cast<float>((static_cast<double>(y - s.up) * s.d_down +
                                                  static_cast<double>(s.down - y) * s.d_up) /
                                                 gap);  // Eq. 3
      if (p) p[x] = d;
      if (c)
        c[x] = d > 0.f ? s.agree * confidence_model->nearness(std::min(y - s.up, s.down - y)) : 0.f;
    }
  }
}

}  // namespace lidar_stereo_fusion
