#include "lidar_stereo_fusion/ros/rate_governor.h"

#include <algorithm>
#include <sstream>

namespace lidar_stereo_fusion {

namespace {

std::string sizeText(int scale) {
  return scale == 1 ? "full size" : "1/" + std::to_string(scale) + " size";
}

std::string msText(double ms) { return std::to_string(static_cast<int>(ms + 0.5)) + " ms"; }

}  // namespace

std::string EffortStep::describe() const {
  return "search from " + sizeText(coarsest_scale) +
         ", pixels without scan-line bounds searched down to " + sizeText(unbounded_scale) + ", " +
         std::to_string(iterations) + (iterations == 1 ? " sweep" : " sweeps") +
         " at the coarsest level" +
         (refine_between ? ""
                         : ", the right view not refined between the coarsest level and full size");
}

std::vector<EffortStep> effortSteps(const FusionParams& base) {
  const PatchMatchParams& p = base.patchmatch;
  const auto coarsestOf = [&](int levels) {
    int scale = 1;
    for (int k = 0; k < levels && p.coarse_scale > 1; ++k) scale *= p.coarse_scale;
    return scale;
  };
  // Pixels without bounds are searched no finer than the finest level that searches at all.
  std::vector<EffortStep> steps{EffortStep{p.coarse_levels, coarsestOf(p.coarse_levels),
                                           std::max(p.unbounded_scale, p.search_scale),
                                           p.iterations, true}};
  if (!isFused(base.method) || p.coarse_levels < 1 || p.coarse_scale < 2) return steps;
  const int coarsest = coarsestOf(p.coarse_levels);
  const bool extra_level = p.coarse_levels < PatchMatchParams::kMaxCoarseLevels;
  const auto deeper = [&](EffortStep e) {
    e.coarse_levels = p.coarse_levels + 1;
    e.coarsest_scale = coarsestOf(e.coarse_levels);
    return e;
  };
  EffortStep s = steps.back();
  // Where a level between the coarsest and the finest refines its right view and hands it back
  // (the default), giving that up is the first step, and after it a coarser search without
  // bounds costs less above the LiDAR than one more level, which comes last (KITTI frame 0, the
  // default: 2.2, 1.8, 1.5, 1.3x SGBM, then 1.1x with one more level; one more level right after
  // the first step: 1.6x, with 1.4 times the error above the LiDAR of the 1.5x step). Where they
  // only propagate (`live`): for each scale pixels without bounds are searched down to, from the
  // configured one to the configured coarsest level, the configured levels, then one more level
  // (1.00, 0.80, 0.74, 0.58x SGBM). Each step is faster than the one before (doc/performance.md).
  const bool refine_first = p.intermediate_refine && p.coarse_levels >= 2;
  if (refine_first) {
    s.refine_between = false;
    steps.push_back(s);
  }
  for (;;) {
    if (extra_level && (!refine_first || s.unbounded_scale >= coarsest)) steps.push_back(deeper(s));
    if (s.unbounded_scale >= coarsest) break;
    s.unbounded_scale *= p.coarse_scale;
    steps.push_back(s);
  }
  // One sweep at the coarsest level, where no level could be added: at 1/8 size the coarsest
  // level's sweeps cost little, and one sweep there doubles the error above the LiDAR (synthetic
  // street, `live`: 0.58x -> 0.56x SGBM, 1.5 -> 2.7 px; 1/4 size: 0.74x -> 0.69x). Without an
  // added level, `s` is the last step.
  if (!extra_level && s.iterations > 1) {
    s.iterations = 1;
    steps.push_back(s);
  }
  return steps;
}

void RateGovernor::rebase(const FusionParams& base) {
  base_ = base;
  steps_ = effortSteps(base);
  leaving_.assign(steps_.size(), 0.0);
  arrived_.assign(steps_.size(), 0.0);
  changeStep(0, "");
}

FusionParams RateGovernor::params() const {
  if (step_ == 0) return base_;
  FusionParams p = base_;
  p.patchmatch.coarse_levels = current().coarse_levels;
  p.patchmatch.unbounded_scale = current().unbounded_scale;
  p.patchmatch.iterations = current().iterations;
  p.patchmatch.intermediate_refine =
      base_.patchmatch.intermediate_refine && current().refine_between;
  return p;
}

double RateGovernor::median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

void RateGovernor::changeStep(int step, const std::string& why) {
  step_ = step;
  late_.clear();
  busy_.clear();
  calm_ = 0;
  reason_ = why;
}

bool RateGovernor::observe(unsigned dropped, double period, double busy_ms) {
  const bool late = dropped > 0;
  late_.push_back(late);
  busy_.push_back(busy_ms);
  if (static_cast<int>(late_.size()) > kWindow) {
    late_.pop_front();
    busy_.pop_front();
  }
  calm_ = late ? 0 : calm_ + 1;
  if (static_cast<int>(late_.size()) < kWindow) return false;
  const double busy = median({busy_.begin(), busy_.end()});
  const size_t s = static_cast<size_t>(step_);
  if (arrived_[s] == 0.0) arrived_[s] = busy;
  const int lates = static_cast<int>(std::count(late_.begin(), late_.end(), true));
  if (lates >= kLateFrames && step_ + 1 < steps()) {
    leaving_[s] = busy;
    std::ostringstream why;
    why << lates << " of the last " << kWindow << " frames were followed by dropped input sets "
        << "(frames take " << msText(busy) << ", median";
    if (period > 0.0) why << ", input every " << msText(1000.0 * period);
    why << ")";
    arrived_[s + 1] = 0.0;
    changeStep(step_ + 1, why.str());
    return true;
  }
  // A step up when the finer step, scaled by how much slower it was than this one when both
  // were measured, would take at most kHeadroom of a period (the host may have calmed down).
  if (step_ > 0 && calm_ >= kCalmFrames && period > 0.0 && arrived_[s] > 0.0 &&
      leaving_[s - 1] > 0.0) {
    const double predicted = busy * leaving_[s - 1] / arrived_[s];
    if (predicted <= kHeadroom * 1000.0 * period) {
      std::ostringstream why;
      why << "no input set dropped in " << calm_ << " frames (frames take " << msText(busy)
          << ", median; the finer step is predicted at " << msText(predicted) << ", input every "
          << msText(1000.0 * period) << ")";
      changeStep(step_ - 1, why.str());
      return true;
    }
  }
  return false;
}

}  // namespace lidar_stereo_fusion
