// Stage 2, last step: the prior's confidence and the fused method's hole fill, with exact answers
// on hand-made scan lines (readings in core/prior_confidence.h).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/prior_confidence.h"
#include "lidar_stereo_fusion/core/upsampling.h"

namespace lsf = lidar_stereo_fusion;

namespace {

/// Scan lines with one line pixel per (row, column) given; every other pixel empty.
lsf::ScanLines makeLines(int width, int height) {
  lsf::ScanLines lines;
  lines.disparity = cv::Mat1f::zeros(height, width);
  lines.ring = cv::Mat1s(height, width, short(-1));
  return lines;
}

void setLine(lsf::ScanLines& lines, int row, float d, short ring) {
  for (int x = 0; x < lines.disparity.cols; ++x) {
    lines.disparity(row, x) = d;
    lines.ring(row, x) = ring;
  }
}

lsf::PriorConfidenceParams noDecay() {
  lsf::PriorConfidenceParams p;
  p.decay_rows = 0;
  return p;
}

cv::Mat1f confidenceOf(const lsf::ScanLines& lines, const lsf::PriorConfidenceParams& p,
                       const std::vector<cv::Point>& removed = {}) {
  lsf::BIParams bi;
  bi.max_interp_rows = 100;
  const cv::Mat1f prior = lsf::interpolateBetweenScanLines(lines, bi);
  return lsf::priorConfidence(lines, prior, removed, p);
}

}  // namespace

TEST(PriorConfidence, AgreeingLinesAreASurfaceAndOutsideTheLinesIsZero) {
  lsf::ScanLines lines = makeLines(4, 12);
  setLine(lines, 2, 10.f, 0);
  setLine(lines, 8, 10.3f, 1);  // residual 0.3 px <= edge_tolerance 0.5
  const cv::Mat1f c = confidenceOf(lines, noDecay());
  for (int y = 0; y < 12; ++y) {
    const float expected = (y >= 2 && y <= 8) ? 1.f : 0.f;
    EXPECT_EQ(c(y, 1), expected) << "row " << y;
  }
}

TEST(PriorConfidence, DisagreeingLinesFallOffWithTheResidualBeyondTheTolerance) {
  lsf::ScanLines lines = makeLines(3, 10);
  setLine(lines, 1, 10.f, 0);
  setLine(lines, 6, 13.f, 1);  // residual 3 px (no other line to extend a slope from)
  const cv::Mat1f c = confidenceOf(lines, noDecay());
  const float expected = std::exp(-(3.f - 0.5f) / 1.f);
  EXPECT_FLOAT_EQ(c(3, 0), expected);
  EXPECT_FLOAT_EQ(c(5, 2), expected);
  EXPECT_EQ(c(1, 0), 1.f);  // the lines themselves are measured
  EXPECT_EQ(c(6, 0), 1.f);
}

TEST(PriorConfidence, ASlantedSurfaceAcrossThreeLinesIsNotAnEdge) {
  // Ground-like: d rises 0.5 px per row; lines 4 rows apart differ by 2 px, on one plane.
  lsf::ScanLines lines = makeLines(2, 14);
  setLine(lines, 1, 10.f, 0);
  setLine(lines, 5, 12.f, 1);
  setLine(lines, 9, 14.f, 2);
  setLine(lines, 13, 16.f, 3);
  const cv::Mat1f c = confidenceOf(lines, noDecay());
  for (int y = 1; y <= 13; ++y) EXPECT_EQ(c(y, 0), 1.f) << "row " << y;
}

TEST(PriorConfidence, AnOcclusionEdgeBetweenTwoSurfacesIsLowDespiteSlopes) {
  // Two flat surfaces (10 px above, 20 px below): the pair straddling the jump disagrees.
  lsf::ScanLines lines = makeLines(2, 16);
  setLine(lines, 1, 10.f, 0);
  setLine(lines, 5, 10.f, 1);
  setLine(lines, 9, 20.f, 2);
  setLine(lines, 13, 20.f, 3);
  const cv::Mat1f c = confidenceOf(lines, noDecay());
  EXPECT_EQ(c(3, 0), 1.f);
  EXPECT_FLOAT_EQ(c(7, 0), std::exp(-(10.f - 0.5f)));
  EXPECT_EQ(c(11, 0), 1.f);
}

TEST(PriorConfidence, AlgorithmOneRemovalsLowerTheirInterval) {
  lsf::ScanLines lines = makeLines(3, 10);
  setLine(lines, 1, 10.f, 0);
  setLine(lines, 7, 10.f, 1);
  const cv::Mat1f c = confidenceOf(lines, noDecay(), {cv::Point(1, 4)});
  EXPECT_FLOAT_EQ(c(2, 1), 0.3f);
  EXPECT_FLOAT_EQ(c(6, 1), 0.3f);
  EXPECT_EQ(c(4, 0), 1.f);  // other columns keep theirs
  EXPECT_EQ(c(4, 2), 1.f);
}

TEST(PriorConfidence, DistanceFromTheLinesDecaysBeyondNearRows) {
  lsf::ScanLines lines = makeLines(1, 30);
  setLine(lines, 0, 10.f, 0);
  setLine(lines, 20, 10.f, 1);
  lsf::PriorConfidenceParams p;  // near_rows 2, decay_rows 16
  const cv::Mat1f c = confidenceOf(lines, p);
  EXPECT_EQ(c(2, 0), 1.f);
  EXPECT_FLOAT_EQ(c(10, 0), std::exp(-(10.f - 2.f) / 16.f));
  EXPECT_FLOAT_EQ(c(17, 0), std::exp(-(3.f - 2.f) / 16.f));
}

TEST(PriorConfidence, RejectsInvalidParamsAndSizes) {
  lsf::ScanLines lines = makeLines(4, 4);
  const cv::Mat1f prior = cv::Mat1f::zeros(4, 4);
  lsf::PriorConfidenceParams p;
  p.edge_sigma = 0;
  EXPECT_THROW(lsf::priorConfidence(lines, prior, {}, p), std::invalid_argument);
  p = lsf::PriorConfidenceParams();
  p.removed_factor = 1.5;
  EXPECT_THROW(lsf::priorConfidence(lines, prior, {}, p), std::invalid_argument);
  EXPECT_THROW(
      lsf::priorConfidence(lines, cv::Mat1f::zeros(5, 4), {}, lsf::PriorConfidenceParams()),
      std::invalid_argument);
}

TEST(FillPriorHoles, RowGapsTakeTheNearerEndRowEndsAndTheBottomAreExtended) {
  cv::Mat1f prior = cv::Mat1f::zeros(4, 6);
  cv::Mat1f conf = cv::Mat1f::zeros(4, 6);
  // Row 1: values at x = 1 (5 px) and x = 4 (8 px).
  prior(1, 1) = 5.f;
  prior(1, 4) = 8.f;
  conf(1, 1) = conf(1, 4) = 1.f;
  lsf::PriorConfidenceParams p;
  p.top_extension_rows = 0;  // FillPriorHoles.ExtendsEachColumnsTopValueUp covers it
  const int filled = lsf::fillPriorHoles(prior, conf, p);
  const float row1[6] = {5.f, 5.f, 8.f, 8.f, 8.f, 8.f};
  for (int x = 0; x < 6; ++x) {
    EXPECT_EQ(prior(1, x), row1[x]) << x;
    EXPECT_FLOAT_EQ(conf(1, x), (x == 1 || x == 4) ? 1.f : 0.2f) << x;
    EXPECT_EQ(prior(0, x), 0.f) << "above the top value stays empty";
    EXPECT_EQ(prior(2, x), row1[x]) << "below the bottom value: extended";
    EXPECT_EQ(prior(3, x), row1[x]);
  }
  EXPECT_EQ(filled, 4 + 2 * 6);
}

TEST(FillPriorHoles, ARowFillNeverCarriesANearerValueAboveAColumnsTop) {
  // A near pole's top point (40 px) sits at row 0 in column 0; the far facade's top line (13 px)
  // is at row 2 in columns 1..5, except column 3, whose top beam returned nothing: its top is the
  // ground (20 px) at row 3.
  cv::Mat1f prior = cv::Mat1f::zeros(5, 6);
  cv::Mat1f conf = cv::Mat1f::zeros(5, 6);
  for (int y = 0; y < 5; ++y) prior(y, 0) = 40.f;
  for (int x = 1; x < 6; ++x) {
    if (x != 3) prior(2, x) = 13.f;
    for (int y = 3; y < 5; ++y) prior(y, x) = 20.f;
  }
  lsf::PriorConfidenceParams p;
  p.top_extension_rows = 0;
  lsf::fillPriorHoles(prior, conf, p);
  for (int x = 1; x < 6; ++x) {
    EXPECT_EQ(prior(0, x), 0.f) << "no near band above the facade's top, column " << x;
    EXPECT_EQ(prior(1, x), 0.f) << x;
  }
  EXPECT_EQ(prior(2, 3), 13.f) << "the facade seen beside a dropout fills it (not nearer)";
  EXPECT_FLOAT_EQ(conf(2, 3), 0.2f);
  EXPECT_EQ(prior(2, 1), 13.f) << "measured values stay";
}

TEST(FillPriorHoles, ExtendsEachColumnsTopValueUpByTopExtensionRows) {
  // Column 0: a near pole from row 2 (40 px); column 1: a far facade from row 5 (13 px); column
  // 2: no LiDAR at all.
  cv::Mat1f prior = cv::Mat1f::zeros(8, 3);
  cv::Mat1f conf = cv::Mat1f::zeros(8, 3);
  for (int y = 2; y < 8; ++y) prior(y, 0) = 40.f;
  for (int y = 5; y < 8; ++y) prior(y, 1) = 13.f;
  lsf::PriorConfidenceParams p;
  p.top_extension_rows = 3;
  const int filled = lsf::fillPriorHoles(prior, conf, p);
  // The row fill gives column 1 nothing nearer than its top (13 px) above row 5, and column 2
  // the row's last value (40 in rows 2-4, 13 in rows 5-7); then each column's top value goes up
  // 3 rows (column 2's filled one too).
  const float expected[8][3] = {{40, 0, 40},  {40, 0, 40},  {40, 13, 40}, {40, 13, 40},
                                {40, 13, 40}, {40, 13, 13}, {40, 13, 13}, {40, 13, 13}};
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 3; ++x) EXPECT_EQ(prior(y, x), expected[y][x]) << x << "," << y;
  }
  EXPECT_FLOAT_EQ(conf(1, 0), 0.2f);
  EXPECT_FLOAT_EQ(conf(2, 1), 0.2f);
  EXPECT_EQ(conf(2, 0), 0.f) << "measured values keep their confidence";
  EXPECT_EQ(filled, 6 + 2 + 3 + 2);  // rows, then the three columns' extensions
}

TEST(FillPriorHoles, ZeroHoleConfidenceFillsNothing) {
  cv::Mat1f prior = cv::Mat1f::zeros(2, 3);
  prior(0, 0) = 4.f;
  cv::Mat1f conf = prior.clone();
  lsf::PriorConfidenceParams p;
  p.hole_confidence = 0;
  EXPECT_EQ(lsf::fillPriorHoles(prior, conf, p), 0);
  EXPECT_EQ(cv::countNonZero(prior), 1);
}
