// LSF_SIMD: the tools' cap on the SIMD path of the matching cost (io/simd_env.h).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/simd_env.h"

namespace lsf = lidar_stereo_fusion;

namespace {

/// Sets (or unsets, for nullptr) LSF_SIMD while a test runs, and restores it when it ends.
class SimdEnvironment {
 public:
  explicit SimdEnvironment(const char* value) {
    const char* old = std::getenv("LSF_SIMD");
    had_ = old != nullptr;
    if (had_) saved_ = old;
    set(value);
  }
  ~SimdEnvironment() { set(had_ ? saved_.c_str() : nullptr); }
  void set(const char* value) {
    if (value == nullptr) {
      unsetenv("LSF_SIMD");
    } else {
      setenv("LSF_SIMD", value, 1);
    }
  }

 private:
  bool had_ = false;
  std::string saved_;
};

}  // namespace

TEST(SimdEnv, ToolsTakeThePathFromLsfSimd) {
  const lsf::SimdPath widest = lsf::widestSimdPath();
  SimdEnvironment env(nullptr);
  EXPECT_EQ(lsf::simdPathFromEnvironment(), widest);  // unset: the widest
  env.set("");
  EXPECT_EQ(lsf::simdPathFromEnvironment(), widest);
  env.set("baseline");
  EXPECT_EQ(lsf::simdPathFromEnvironment(), lsf::SimdPath::kBaseline);
  env.set("avx2");  // a cap: baseline on a CPU without AVX2
  EXPECT_EQ(lsf::simdPathFromEnvironment(), lsf::capSimdPath(lsf::SimdPath::kAvx2));
  env.set("avx512");
  EXPECT_EQ(lsf::simdPathFromEnvironment(), widest);
  env.set("fastest");
  std::string warning;
  EXPECT_EQ(lsf::simdPathFromEnvironment(&warning), widest);
  EXPECT_NE(warning.find("LSF_SIMD=fastest is not baseline, avx2 or avx512"), std::string::npos)
      << warning;
  env.set("baseline");
  lsf::FusionParams params;
  EXPECT_EQ(lsf::applySimdEnvironment(params), lsf::SimdPath::kBaseline);
  EXPECT_EQ(params.patchmatch.simd_path, lsf::SimdPath::kBaseline);
}
