// The parameter table (core/param_table.h): one wording for a value out of range, every default
// within its row's range, and every struct's validate() refusing each row's first value outside it.
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/param_table.h"
#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

namespace lidar_stereo_fusion {
namespace {

TEST(ParamSpec, OneSentenceForAValueOutOfRange) {
  const ParamSpec radius{"window_radius", "patchmatch", within(1, 50), "px", "doc"};
  EXPECT_EQ(rangeProblem(radius, 8), "");
  EXPECT_EQ(rangeProblem(radius, 1), "");
  EXPECT_EQ(rangeProblem(radius, 50), "");
  EXPECT_EQ(rangeProblem(radius, 0), "window_radius must be in [1, 50] px, got 0");
  EXPECT_EQ(rangeProblem(radius, 51), "window_radius must be in [1, 50] px, got 51");
  const ParamSpec depth{"min_depth", "projection", above(0), "m", "doc"};
  EXPECT_EQ(rangeProblem(depth, 0.0), "min_depth must be > 0 m, got 0");
  EXPECT_EQ(rangeProblem(depth, -0.25), "min_depth must be > 0 m, got -0.25");
  EXPECT_EQ(rangeProblem(depth, std::numeric_limits<double>::infinity()),
            "min_depth must be > 0 m, got inf");
  EXPECT_EQ(rangeProblem(depth, std::nan("")), "min_depth must be > 0 m, got nan");
  const ParamSpec time{"max_point_time", "motion", aboveUpTo(0, 10), "s", "doc"};
  EXPECT_EQ(rangeProblem(time, 10), "");
  EXPECT_EQ(rangeProblem(time, 0), "max_point_time must be in (0, 10] s, got 0");
  const ParamSpec any{"x", "", anyFinite(), "", "doc"};
  EXPECT_EQ(rangeProblem(any, -1e300), "");
  EXPECT_EQ(rangeProblem(any, std::nan("")), "x must be finite, got nan");
  const ParamSpec word{"motion_failure", "", {}, "", "doc", "uncompensated|skip"};
  EXPECT_EQ(choiceProblem(word, "skip"), "");
  EXPECT_EQ(choiceProblem(word, "drop"),
            "motion_failure must be one of uncompensated, skip, got 'drop'");
}

TEST(ParamTable, NamesAreUniqueAndEveryDefaultIsWithinItsRange) {
  std::set<std::string> names;
  visitParamTable(FusionParams(), [&](const ParamSpec& s, const auto&) {
    const std::string name = s.name, doc = s.doc;
    EXPECT_TRUE(names.insert(name).second) << name << " twice";
    EXPECT_FALSE(doc.empty()) << name;
    EXPECT_EQ(doc.find('\n'), std::string::npos) << name << ": one line";
  });
  EXPECT_GT(names.size(), 40u);
  EXPECT_NO_THROW(visitParamTable(FusionParams(), RangeChecker{"defaults"}));
  EXPECT_NO_THROW(FusionParams().validate());
}

TEST(ParamTable, NamedLimitsAreTheRangesAndTheKernelsBuffers) {
  double radius_hi = 0, threads_hi = 0;
  visitParamTable(FusionParams(), [&](const ParamSpec& s, const auto&) {
    if (std::string(s.name) == "window_radius") radius_hi = s.range.hi;
    if (std::string(s.name) == "num_threads") threads_hi = s.range.hi;
  });
  EXPECT_EQ(radius_hi, PatchMatchParams::kMaxWindowRadius);
  EXPECT_EQ(threads_hi, PatchMatchParams::kMaxThreads);
  EXPECT_EQ(patchmatch::kMaxWindowOffsets, 2 * PatchMatchParams::kMaxWindowRadius + 1);
  PatchMatchParams p;
  p.window_radius = PatchMatchParams::kMaxWindowRadius;
  p.window_stride = 1;
  p.window_dyadic = false;
  EXPECT_NO_THROW(p.validate()) << "the largest window is allowed";
}

/// Sets the k-th numeric row of the table just outside its range (below the lower end, else
/// above the upper end) and records its name and whether it could.
struct BreakRow {
  int k;
  std::string name;
  int seen = 0;
  template <class T>
  void operator()(const ParamSpec& s, T& value) {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (seen++ != k) return;
      const double lo = s.range.lo, hi = s.range.hi;
      if (std::isfinite(lo) && (std::is_signed_v<T> || lo > 0)) {
        value = static_cast<T>(std::is_integral_v<T> ? lo - 1 : (s.range.lo_open ? lo : lo - 1e-3));
        name = s.name;
      } else if (std::isfinite(hi)) {
        value = static_cast<T>(std::is_integral_v<T> ? hi + 1 : hi + 1e-3);
        name = s.name;
      }
    }
  }
};

TEST(ParamTable, ValidateRefusesEveryRowJustOutsideItsRangeNamingIt) {
  int refused = 0;
  for (int k = 0;; ++k) {
    FusionParams p;
    BreakRow breaker{k, ""};
    visitParamTable(p, breaker);
    if (k >= breaker.seen) break;
    if (breaker.name.empty()) continue;  // unbounded (the seed)
    try {
      p.validate();
      ADD_FAILURE() << breaker.name << " out of its range was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(breaker.name + " must be"), std::string::npos)
          << e.what();
      ++refused;
    }
  }
  EXPECT_GT(refused, 40);
}

TEST(ParamTable, ChecksBetweenParametersStayInValidate) {
  FusionParams p;
  p.projection.max_depth = p.projection.min_depth;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FusionParams();
  p.patchmatch.alpha = 0.5;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FusionParams();
  p.patchmatch.right_iterations = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FusionParams();
  p.patchmatch.window_stride = p.patchmatch.window_radius + 1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = FusionParams();
  p.bf.radius = 1;
  p.bf.min_support = 10;
  try {
    p.validate();
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "BFParams: min_support must be <= 9 (the window's pixels), got 10");
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
