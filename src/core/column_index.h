// The non-empty pixels of a disparity map grouped by column (CSR layout): the column-wise steps of
// stage 2 (Algorithm 1, Eq. 3, search bounds, prior confidence) walk scan lines column by column.
// Private to the core.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// One scan-line pixel of a column: row and disparity.
struct ColumnEntry {
  int y;
  float d;
};

/// The non-empty pixels of a map grouped by column, each column top to bottom (CSR layout).
class ColumnIndex {
 public:
  explicit ColumnIndex(const cv::Mat1f& map) : begin_(map.cols + 1, 0) {
    for (int y = 0; y < map.rows; ++y) {
      const float* row = map[y];
      for (int x = 0; x < map.cols; ++x) {
        if (row[x] > 0.f) ++begin_[x + 1];
      }
    }
    for (int x = 0; x < map.cols; ++x) begin_[x + 1] += begin_[x];
    entries_.resize(begin_[map.cols]);
    std::vector<int> next(begin_.begin(), begin_.end() - 1);
    for (int y = 0; y < map.rows; ++y) {
      const float* row = map[y];
      for (int x = 0; x < map.cols; ++x) {
        if (row[x] > 0.f) entries_[next[x]++] = {y, row[x]};
      }
    }
  }
  int cols() const { return static_cast<int>(begin_.size()) - 1; }
  /// Removes the entries at `pixels` (x = column, y = row; each an entry of this index, ordered
  /// by column, then row, as removeOccludedPoints collects them): the index of the map with those
  /// pixels cleared, in one pass over the entries instead of two over the map.
  void erase(const std::vector<cv::Point>& pixels) {
    if (pixels.empty()) return;
    size_t next = 0, kept = 0;
    int start = 0;  // the column's first entry before compaction
    for (int x = 0; x < cols(); ++x) {
      const int end = begin_[x + 1];
      begin_[x] = static_cast<int>(kept);
      for (int k = start; k < end; ++k) {
        if (next < pixels.size() && pixels[next].x == x && pixels[next].y == entries_[k].y) {
          ++next;
          continue;
        }
        entries_[kept++] = entries_[k];
      }
      start = end;
    }
    begin_[cols()] = static_cast<int>(kept);
    entries_.resize(kept);
  }
  /// Number of entries in column x.
  int size(int x) const { return begin_[x + 1] - begin_[x]; }
  /// First entry of column x (entries are ordered by row).
  const ColumnEntry* column(int x) const { return entries_.data() + begin_[x]; }

 private:
  std::vector<int> begin_;
  std::vector<ColumnEntry> entries_;
};

}  // namespace lidar_stereo_fusion
