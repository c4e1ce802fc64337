// lsf_demo's pictures: the reference, the LiDAR, the BI* prior and its confidence, the methods'
// disparities and errors, each as a PNG, and a composite of them in rows of two.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "demo_case.h"
#include "lidar_stereo_fusion/io/visualization.h"

namespace lsf_demo {

namespace fs = std::filesystem;

namespace {

const MethodRun* findRun(const std::vector<MethodRun>& runs, lsf::Method m) {
  for (const MethodRun& r : runs) {
    if (r.method == m) return &r;
  }
  return nullptr;
}

/// A picture with a caption band above it, scaled to `width`.
cv::Mat captioned(const cv::Mat& image, const std::string& caption, int width) {
  cv::Mat scaled;
  const double s = static_cast<double>(width) / image.cols;
  cv::resize(image, scaled, cv::Size(width, static_cast<int>(std::lround(image.rows * s))), 0, 0,
             s < 1 ? cv::INTER_AREA : cv::INTER_NEAREST);
  constexpr int kBand = 22;
  cv::Mat out(scaled.rows + kBand, width, CV_8UC3, cv::Scalar(30, 30, 30));
  scaled.copyTo(out(cv::Rect(0, kBand, width, scaled.rows)));
  cv::putText(out, caption, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  return out;
}

/// Tiles in rows of two.
cv::Mat composite(const std::vector<std::pair<cv::Mat, std::string>>& tiles, int tile_width) {
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < tiles.size(); i += 2) {
    cv::Mat a = captioned(tiles[i].first, tiles[i].second, tile_width);
    cv::Mat b = i + 1 < tiles.size()
                    ? captioned(tiles[i + 1].first, tiles[i + 1].second, tile_width)
                    : cv::Mat(a.size(), a.type(), cv::Scalar(30, 30, 30));
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{a, cv::Mat(a.rows, 4, CV_8UC3, cv::Scalar(0, 0, 0)), b}, row);
    rows.push_back(row);
    rows.push_back(cv::Mat(4, row.cols, CV_8UC3, cv::Scalar(0, 0, 0)));
  }
  rows.pop_back();
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

/// Absolute disparity error at sparse reference pixels, drawn as dots over the darkened image.
cv::Mat errorDots(const cv::Mat& image, const cv::Mat1f& estimate, const cv::Mat1f& reference,
                  double max_error) {
  cv::Mat canvas;
  image.convertTo(canvas, -1, 0.4);
  const cv::Mat colours = lsf::colorizeError(estimate, reference, max_error);
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      if (!(reference(y, x) > 0.f)) continue;
      const cv::Vec3b c = colours.at<cv::Vec3b>(y, x);
      cv::circle(canvas, cv::Point(x, y), 1, cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    }
  }
  return canvas;
}

void writeImage(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) {
    throw std::runtime_error("cannot write " + path.string());
  }
}

}  // namespace

fs::path writePictures(const DemoCase& c, const std::vector<MethodRun>& runs, const fs::path& out) {
  fs::create_directories(out);
  const lsf::StereoCamera& cam = c.input.camera;
  const cv::Mat1f reference = lsf::depthToDisparity(c.reference_depth, cam);
  double max_d = 0.0;
  cv::minMaxLoc(reference, nullptr, &max_d);
  constexpr double kMaxError = 4.0;  // [px]
  auto error = [&](const cv::Mat1f& estimate) {
    return c.dense_reference ? lsf::colorizeError(estimate, reference, kMaxError)
                             : errorDots(c.input.left, estimate, reference, kMaxError);
  };

  std::vector<std::pair<cv::Mat, std::string>> tiles;  // the composite: rows of two
  auto add = [&](const std::string& file, const cv::Mat& image, const std::string& caption,
                 bool in_composite = true) {
    writeImage(out / file, image);
    if (in_composite) tiles.emplace_back(image, caption);
  };
  add("left.png", c.input.left, "left image");
  add("reference.png",
      c.dense_reference ? lsf::colorizeDisparity(reference, max_d)
                        : lsf::overlaySparse(c.input.left, reference, max_d),
      c.dense_reference ? "exact ground-truth disparity" : "held-out LiDAR rings (reference)");
  if (!runs.empty()) {
    add("lidar_overlay.png",
        lsf::overlaySparse(c.input.left, runs.front().result.sparse.disparity, max_d),
        c.dense_reference ? "LiDAR projected into the left image"
                          : "LiDAR fed to the method (even rings)");
  }
  if (const MethodRun* r = findRun(runs, lsf::Method::kFusedBI)) {
    add("prior_bi.png", lsf::colorizeDisparity(r->result.prior, max_d), "BI* up-sampled LiDAR");
    add("prior_confidence.png", lsf::colorizeConfidence(r->result.confidence, r->result.prior),
        "confidence of the prior (dark 0 .. yellow 1)");
  }
  for (lsf::Method m : {lsf::Method::kFusedBI, lsf::Method::kPlainPMS, lsf::Method::kFusedBF}) {
    const MethodRun* r = findRun(runs, m);
    if (!r) continue;
    const std::string name = lsf::methodName(m);
    add(name + "_disparity.png", lsf::colorizeDisparity(r->result.disparity, max_d),
        m == lsf::Method::kPlainPMS ? "PMS (stereo only) disparity" : name + " disparity",
        m != lsf::Method::kFusedBF);
  }
  for (lsf::Method m : {lsf::Method::kFusedBI, lsf::Method::kPlainPMS}) {
    const MethodRun* r = findRun(runs, m);
    if (!r) continue;
    const std::string name = lsf::methodName(m);
    add(name + "_error.png", error(r->result.disparity),
        name + " disparity error (blue 0 .. red " + std::to_string(static_cast<int>(kMaxError)) +
            "+ px)");
  }
  const fs::path composite_path = out / "composite.png";
  writeImage(composite_path, composite(tiles, std::min(620, cam.width)));
  return composite_path;
}

}  // namespace lsf_demo
