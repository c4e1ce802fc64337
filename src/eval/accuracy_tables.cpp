// Markdown tables of the accuracy protocols.
#include "lidar_stereo_fusion/eval/accuracy_tables.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <utility>

#include "lidar_stereo_fusion/eval/report.h"

namespace lidar_stereo_fusion {
namespace {

using table::format;
using table::row;
using table::separator;

const std::vector<Region> kSplitRegions = {Region::kAbove, Region::kAboveBothViews, Region::kInside,
                                           Region::kEdge, Region::kElsewhere};
const std::vector<Region> kBands = {Region::kAll, Region::kNear, Region::kMid, Region::kFar,
                                    Region::kTopRows};

/// Adds "raw coverage %" and "ms / <item>" (the method's wall time per scene / frame) columns to a
/// table from report.h (same row order).
template <typename Metrics>
std::string withExtraColumns(const std::string& table, const LayoutScores<Metrics>& layout,
                             const std::string& item) {
  const double items = std::max<size_t>(1, layout.items.size());
  std::string out;
  size_t start = 0;
  for (int line = 0; start < table.size(); ++line) {
    const size_t end = table.find('\n', start);
    std::string text = table.substr(start, end - start);
    if (line == 0) {
      text += " raw coverage % | ms / " + item + " |";
    } else if (line == 1) {
      text += "---|---|";
    } else {
      const MethodScores<Metrics>& m = layout.methods[line - 2];
      text += " " + format("%.1f", 100 * m.raw_coverage) + " | " +
              format("%.1f", 1000 * m.seconds / items) + " |";
    }
    out += text + "\n";
    start = end + 1;
  }
  return out;
}

template <typename Metrics, typename Cells>
std::string regionTable(const LayoutScores<Metrics>& layout, const std::vector<Region>& regions,
                        const char* first, const char* second, Cells cells) {
  std::vector<std::string> header = {"method"};
  for (Region r : regions) {
    header.push_back(regionName(r) + " " + first);
    header.push_back(regionName(r) + " " + second);
  }
  std::string out = row(header) + separator(header.size());
  for (const MethodScores<Metrics>& m : layout.methods) {
    std::vector<std::string> line = {m.name};
    for (Region r : regions) {
      const auto pair = cells(m.mean[static_cast<int>(r)]);
      line.push_back(pair.first);
      line.push_back(pair.second);
    }
    out += row(line);
  }
  if (!layout.methods.empty()) {
    const auto& mean = layout.methods.front().mean;
    const double all = std::max(1, mean[static_cast<int>(Region::kAll)].count);
    std::vector<std::string> line = {"share of pixels %"};
    for (Region r : regions) {
      line.push_back(format("%.1f", 100.0 * mean[static_cast<int>(r)].count / all));
      line.push_back("");
    }
    out += row(line);
  }
  return out;
}

/// "N (P %)": a count and its share of `total`.
std::string share(long n, long total) {
  return std::to_string(n) + " (" + format("%.1f", 100.0 * n / std::max(1L, total)) + " %)";
}

}  // namespace

std::string formatMiddleburyLayout(const LayoutScores<DisparityMetrics>& layout) {
  std::vector<DisparityRow> rows;
  for (const auto& m : layout.methods) rows.push_back({m.name, m.mean[0]});
  std::string out = withExtraColumns(formatDisparityTable(rows), layout, "scene");
  std::vector<std::string> header = {"method"};
  for (const std::string& item : layout.items) {
    header.push_back(item + " MAE px");
    header.push_back(item + " >2 px %");
  }
  out += "\n" + row(header) + separator(header.size());
  for (const auto& m : layout.methods) {
    std::vector<std::string> line = {m.name};
    for (const auto& scores : m.per_item) {
      line.push_back(format("%.3f", scores[0].mae_px));
      line.push_back(format("%.2f", 100 * scores[0].bad2));
    }
    out += row(line);
  }
  return out;
}

std::string formatKittiLayout(const LayoutScores<DepthMetrics>& layout) {
  std::vector<DepthRow> rows;
  for (const auto& m : layout.methods) rows.push_back({m.name, m.mean[0]});
  return withExtraColumns(formatDepthTable(rows), layout, "frame");
}

std::string formatMiddleburyRegions(const LayoutScores<DisparityMetrics>& layout) {
  return regionTable(layout, kSplitRegions, "MAE px", ">2 px %", [](const DisparityMetrics& m) {
    return std::make_pair(format("%.3f", m.mae_px), format("%.2f", 100 * m.bad2));
  });
}

std::string formatKittiRegions(const LayoutScores<DepthMetrics>& layout) {
  return regionTable(layout, kSplitRegions, "MAE mm", ">3 px %", [](const DepthMetrics& m) {
    return std::make_pair(format("%.0f", m.mae_mm), format("%.2f", 100 * m.bad3));
  });
}

std::string formatDepthBands(const LayoutScores<DepthMetrics>& layout) {
  return regionTable(layout, kBands, "MAE mm", "RMSE mm", [](const DepthMetrics& m) {
    return std::make_pair(format("%.0f", m.mae_mm), format("%.0f", m.rmse_mm));
  });
}

namespace {

template <typename Metrics>
std::string edgeSidesTable(const LayoutScores<Metrics>& layout) {
  const std::vector<std::string> header = {
      "method",  "own edge pixels with a reference",     "reference near %", "far %", "between %",
      "other %", "share of the method's squared error %"};
  std::string out = row(header) + separator(header.size());
  for (const MethodScores<Metrics>& m : layout.methods) {
    const EdgeSides& e = m.edge_sides;
    const double n = static_cast<double>(std::max<int64_t>(1, e.pixels));
    out += row(
        {m.name, std::to_string(e.pixels), format("%.1f", 100 * e.near / n),
         format("%.1f", 100 * e.far / n), format("%.1f", 100 * e.between / n),
         format("%.1f", 100 * e.other / n),
         format("%.1f", e.total_sq_error > 0 ? 100 * e.edge_sq_error / e.total_sq_error : 0.0)});
  }
  return out;
}

}  // namespace

std::string formatEdgeSides(const LayoutScores<DisparityMetrics>& layout) {
  return edgeSidesTable(layout);
}

std::string formatEdgeSides(const LayoutScores<DepthMetrics>& layout) {
  return edgeSidesTable(layout);
}

std::string formatAccumulatedReference(const kitti::AccumulatedDepth& reference) {
  const long image = static_cast<long>(reference.depth.total());
  const long other = reference.other_points;
  std::string out = row({"reference", "value"}) + separator(2);
  out += row({"sweeps accumulated (the own one included)", std::to_string(reference.sweeps)});
  out += row({"pixels with a reference (of the image)", share(reference.pixels, image)});
  out += row({"of them with an own-sweep point", share(reference.own_pixels, reference.pixels)});
  out += row({"other sweeps' points in the image", std::to_string(other)});
  out += row({reference.unverified_kept ? "kept unverified: no own point in the check window"
                                        : "removed: no own point in the check window",
              share(reference.removed_unverified, other)});
  out += row({"removed: outside the window's own depth range",
              share(reference.removed_disagreeing, other)});
  out += row({"other vs own sweep before removal: relative difference median / p90 %",
              format("%.2f", 100 * reference.median_relative_difference) + " / " +
                  format("%.2f", 100 * reference.p90_relative_difference) + " over " +
                  std::to_string(reference.compared_pixels) + " pixels"});
  return out;
}

std::string formatStereoCheck(const StereoCheckCounts& counts, double max_diff_px) {
  if (!(max_diff_px > 0.0)) return "";
  return row({"stereo check: reference pixels checked", std::to_string(counts.checked)}) +
         row({"removed: SGBM has no disparity there",
              share(counts.removed_no_stereo, counts.checked)}) +
         row({"removed: SGBM differs by more than " + format("%g", max_diff_px) + " px",
              share(counts.removed_disagreeing, counts.checked)});
}

}  // namespace lidar_stereo_fusion
