// Locating ../shared/data for the data-driven tests: a missing folder FAILS under CI=true and is
// skipped otherwise.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace lidar_stereo_fusion {
namespace test {

/// LSF_DATA_DIR/`relative`.
inline std::string dataPath(const std::string& relative) {
  return (std::filesystem::path(LSF_DATA_DIR) / relative).string();
}

inline bool runningUnderCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace test
}  // namespace lidar_stereo_fusion

/// Fails (CI=true) or skips the current test when LSF_DATA_DIR/`relative` does not exist.
#define LSF_REQUIRE_DATA(relative)                                                     \
  do {                                                                                 \
    const std::string lsf_path_ = ::lidar_stereo_fusion::test::dataPath(relative);     \
    if (!std::filesystem::exists(lsf_path_)) {                                         \
      if (::lidar_stereo_fusion::test::runningUnderCi()) {                             \
        FAIL() << "missing test data " << lsf_path_ << " (CI=true: data is required)"; \
      } else {                                                                         \
        GTEST_SKIP() << "missing test data " << lsf_path_ << " (set CI=true to fail)"; \
      }                                                                                \
    }                                                                                  \
  } while (0)
