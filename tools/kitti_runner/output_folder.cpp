// kitti_runner's output folder: creating and probing it, and the pictures of --save-vis.
#include "output_folder.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/io/visualization.h"

namespace kitti_runner {

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

void writeImage(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

void createDirectory(const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw std::runtime_error("cannot create output folder " + dir.string() + ": " +
                             error.message());
  }
}

namespace {

/// `path` absolute, symbolic links resolved, without a trailing separator ("a/b/" -> "a/b").
fs::path resolved(const fs::path& path, std::error_code& error) {
  fs::path p = fs::weakly_canonical(fs::absolute(path), error);
  if (!p.has_filename() && p != p.root_path()) p = p.parent_path();
  return p;
}

}  // namespace

void requireApart(const fs::path& out, const fs::path& input, const std::string& what) {
  std::error_code out_error, input_error;
  const fs::path inner = resolved(out, out_error);
  const fs::path outer = resolved(input, input_error);
  if (out_error || input_error) return;  // the folders' own checks name them
  for (fs::path p = inner; !p.empty(); p = p.parent_path()) {
    if (p == outer) {
      throw std::runtime_error("output folder " + out.string() + " is inside " + what + " " +
                               input.string() +
                               ": kitti_runner does not write among the files it reads (choose a "
                               "folder outside it)");
    }
    if (p == p.parent_path()) break;
  }
}

void requireWritable(const fs::path& dir) {
  const fs::path probe = dir / (".kitti_runner_probe_" + std::to_string(::getpid()));
  FILE* file = std::fopen(probe.string().c_str(), "wb");
  if (file == nullptr) {
    throw std::runtime_error("cannot write into output folder " + dir.string() + ": " +
                             std::strerror(errno));
  }
  std::fclose(file);
  fs::remove(probe);
}

void saveVisualisation(const fs::path& dir, const std::string& name, const cv::Mat& left,
                       const lsf::FusionResult& result, const std::optional<cv::Mat1f>& reference,
                       const lsf::StereoCamera& camera) {
  double max_disparity = 0;
  cv::minMaxLoc(result.sparse.disparity, nullptr, &max_disparity);
  writeImage(dir / (name + "_sparse.png"),
             lsf::withColorBar(lsf::overlaySparse(left, result.sparse.disparity, max_disparity), 0,
                               max_disparity, "px disparity"));
  if (!result.prior.empty()) {
    writeImage(dir / (name + "_prior.png"),
               lsf::withColorBar(lsf::colorizeDisparity(result.prior, max_disparity), 0,
                                 max_disparity, "px disparity"));
    writeImage(dir / (name + "_confidence.png"),
               lsf::withColorBar(lsf::colorizeConfidence(result.confidence, result.prior), 0, 1,
                                 "confidence", cv::COLORMAP_VIRIDIS));
  }
  writeImage(dir / (name + "_disparity.png"),
             lsf::withColorBar(lsf::colorizeDisparity(result.disparity, max_disparity), 0,
                               max_disparity, "px disparity"));
  constexpr double kMaxDepth = 80.0;  ///< [m] colorizeDepth's scale
  writeImage(dir / (name + "_depth.png"),
             lsf::withColorBar(lsf::colorizeDepth(result.depth, kMaxDepth), kMaxDepth, 0, "m"));
  if (reference) {
    constexpr double kMaxError = 5.0;  ///< [px] colorizeError's scale
    writeImage(
        dir / (name + "_error.png"),
        lsf::withColorBar(lsf::colorizeError(result.disparity,
                                             lsf::depthToDisparity(*reference, camera), kMaxError),
                          0, kMaxError, "px error"));
  }
}

}  // namespace kitti_runner
