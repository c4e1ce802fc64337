// Markdown tables of the accuracy protocols.
#include "lidar_stereo_fusion/io/accuracy_tables.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "lidar_stereo_fusion/io/report.h"

namespace lidar_stereo_fusion {
namespace {

using table::format;
using table::row;
using table::separator;

constexpr Region kSplitRegions[] = {Region::kAbove, Region::kInside, Region::kEdge,
                                    Region::kElsewhere};

/// Adds "raw coverage %" and "time s" columns to a table from report.h (same row order).
template <typename Metrics>
std::string withExtraColumns(const std::string& table, const LayoutScores<Metrics>& layout) {
  std::string out;
  size_t start = 0;
  for (int line = 0; start < table.size(); ++line) {
    const size_t end = table.find('\n', start);
    std::string text = table.substr(start, end - start);
    if (line == 0) {
      text += " raw coverage % | time s |";
    } else if (line == 1) {
      text += "---|---|";
    } else {
      const MethodScores<Metrics>& m = layout.methods[line - 2];
      text += " " + format("%.1f", 100 * m.raw_coverage) + " | " + format("%.1f", m.seconds) + " |";
    }
    out += text + "\n";
    start = end + 1;
  }
  return out;
}

template <typename Metrics, typename Cells>
std::string regionTable(const LayoutScores<Metrics>& layout, const char* first, const char* second,
                        Cells cells) {
  std::vector<std::string> header = {"method"};
  for (Region r : kSplitRegions) {
    header.push_back(regionName(r) + " " + first);
    header.push_back(regionName(r) + " " + second);
  }
  std::string out = row(header) + separator(header.size());
  for (const MethodScores<Metrics>& m : layout.methods) {
    std::vector<std::string> line = {m.name};
    for (Region r : kSplitRegions) {
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
    for (Region r : kSplitRegions) {
      line.push_back(format("%.1f", 100.0 * mean[static_cast<int>(r)].count / all));
      line.push_back("");
    }
    out += row(line);
  }
  return out;
}

}  // namespace

std::string formatMiddleburyLayout(const LayoutScores<DisparityMetrics>& layout) {
  std::vector<DisparityRow> rows;
  for (const auto& m : layout.methods) rows.push_back({m.name, m.mean[0]});
  std::string out = withExtraColumns(formatDisparityTable(rows), layout);
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
  return withExtraColumns(formatDepthTable(rows), layout);
}

std::string formatMiddleburyRegions(const LayoutScores<DisparityMetrics>& layout) {
  return regionTable(layout, "MAE px", ">2 px %", [](const DisparityMetrics& m) {
    return std::make_pair(format("%.3f", m.mae_px), format("%.2f", 100 * m.bad2));
  });
}

std::string formatKittiRegions(const LayoutScores<DepthMetrics>& layout) {
  return regionTable(layout, "MAE mm", ">3 px %", [](const DepthMetrics& m) {
    return std::make_pair(format("%.0f", m.mae_mm), format("%.2f", 100 * m.bad3));
  });
}

}  // namespace lidar_stereo_fusion
