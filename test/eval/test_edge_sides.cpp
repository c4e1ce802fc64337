// edgeSides (eval/edge_sides.h) with exact answers: which surface a reference has at an output's
// own depth edges.
#include <gtest/gtest.h>

#include <stdexcept>

#include "lidar_stereo_fusion/eval/edge_sides.h"

namespace lidar_stereo_fusion {
namespace {

/// 4 columns x 6 rows: rows 0-2 at `far_value`, rows 3-5 at `near_value`. The edge pixels are
/// row 2's (their neighbour below is nearer); row 3's nearest neighbour is their own surface.
cv::Mat1f twoSurfaces(float far_value, float near_value) {
  cv::Mat1f m(6, 4, far_value);
  m.rowRange(3, 6).setTo(near_value);
  return m;
}

/// Row 2's four edge pixels, one reference of each class.
void expectOneOfEachOnRowTwo(const EdgeSides& s) {
  EXPECT_EQ(s.pixels, 4);
  EXPECT_EQ(s.near, 1);
  EXPECT_EQ(s.far, 1);
  EXPECT_EQ(s.between, 1);
  EXPECT_EQ(s.other, 1);
}

TEST(EdgeSides, DepthOutputCountsEachClassOfTheReferenceOnRowTwo) {
  const cv::Mat1f out = twoSurfaces(20.f, 10.f);
  cv::Mat1f ref(6, 4, 0.f);
  ref(2, 0) = 10.f;   // near (the neighbour's surface)
  ref(2, 1) = 20.5f;  // far: within 10 % of the pixel's own 20 m
  ref(2, 2) = 15.f;   // between
  ref(2, 3) = 5.f;    // other: nearer than the near surface
  ref(0, 0) = 21.f;   // not an edge pixel: only the total
  ref(4, 1) = 10.f;   // near side, no error
  const EdgeSides s = edgeSides(out, ref, MapKind::kDepth);
  expectOneOfEachOnRowTwo(s);
  EXPECT_DOUBLE_EQ(s.edge_sq_error, 100.0 + 0.25 + 25.0 + 225.0);
  EXPECT_DOUBLE_EQ(s.total_sq_error, 100.0 + 0.25 + 25.0 + 225.0 + 1.0);
}

TEST(EdgeSides, DisparityIsComparedAsItsDepthAndErrorsStayInPixels) {
  const cv::Mat1f out = twoSurfaces(5.f, 10.f);  // 5 px is the far surface
  cv::Mat1f ref(6, 4, 0.f);
  ref(2, 0) = 10.f;  // near
  ref(2, 1) = 5.2f;  // far: 1 / 5.2 within 10 % of 1 / 5
  ref(2, 2) = 7.f;   // between (1 / 7 is in neither tolerance)
  ref(2, 3) = 20.f;  // other: nearer than the near surface
  const EdgeSides s = edgeSides(out, ref, MapKind::kDisparity);
  expectOneOfEachOnRowTwo(s);
  EXPECT_NEAR(s.edge_sq_error, 25.0 + 0.04 + 4.0 + 225.0, 1e-4);
}

TEST(EdgeSides, AStepBelowTheRatioIsNoEdgeAndEmptyPixelsAreFilledAsScored) {
  const cv::Mat1f out = twoSurfaces(12.5f, 10.f);  // ratio 1.25
  const cv::Mat1f ref = twoSurfaces(12.5f, 10.f);
  EXPECT_EQ(edgeSides(out, ref, MapKind::kDepth).pixels, 0);
  EXPECT_EQ(edgeSides(out, ref, MapKind::kDepth, 1.2).pixels, 4);
  EXPECT_EQ(edgeSides(out, ref, MapKind::kDepth, 1.2).far, 4);
  // An empty output pixel inside row 0 takes the nearer of its row neighbours (the devkit): no
  // error, no edge.
  cv::Mat1f holed = twoSurfaces(20.f, 10.f);
  holed(0, 1) = 0.f;
  cv::Mat1f ref2(6, 4, 0.f);
  ref2(0, 1) = 20.f;
  const EdgeSides s = edgeSides(holed, ref2, MapKind::kDepth);
  EXPECT_EQ(s.pixels, 0);
  EXPECT_DOUBLE_EQ(s.total_sq_error, 0.0);
}

TEST(EdgeSides, SumsAddUp) {
  const cv::Mat1f out = twoSurfaces(20.f, 10.f);
  const cv::Mat1f ref = twoSurfaces(20.f, 10.f);
  EdgeSides s = edgeSides(out, ref, MapKind::kDepth);
  s += edgeSides(out, ref, MapKind::kDepth);
  EXPECT_EQ(s.pixels, 8);
  EXPECT_EQ(s.far, 8);
  EXPECT_EQ(s.near + s.between + s.other, 0);
}

TEST(EdgeSides, RejectsSizeMismatchAndAbsurdThresholds) {
  const cv::Mat1f out = twoSurfaces(20.f, 10.f);
  EXPECT_THROW(edgeSides(out, cv::Mat1f(5, 4, 1.f), MapKind::kDepth), std::invalid_argument);
  EXPECT_THROW(edgeSides(out, out, MapKind::kDepth, 1.0), std::invalid_argument);
  EXPECT_THROW(edgeSides(out, out, MapKind::kDepth, 1.3, 1.0), std::invalid_argument);
  EXPECT_THROW(edgeSides(out, out, MapKind::kDepth, 1.3, -0.1), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
