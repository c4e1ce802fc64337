// The dense-LiDAR protocol: frame 20's full sweep in, the accumulated reference out.
#include "lidar_stereo_fusion/eval/accuracy_dense.h"

#include <algorithm>
#include <filesystem>
#include <ostream>
#include <stdexcept>

#include "accuracy_common.h"
#include "lidar_stereo_fusion/eval/report.h"

namespace lidar_stereo_fusion {

DenseProtocolResult runDenseProtocol(const AccuracyOptions& options,
                                     const kitti::AccumulationParams& reference_params,
                                     double stereo_check_px) {
  using namespace accuracy_detail;
  using table::format;
  options.validate();
  const std::string drive =
      (std::filesystem::path(options.data_dir) / "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync")
          .string();
  if (!std::filesystem::is_directory(drive)) {
    throw std::runtime_error("KITTI drive not found: " + drive);
  }
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  const auto frame = std::find_if(frames.begin(), frames.end(),
                                  [](const kitti::Frame& f) { return f.name == kDenseFrame; });
  if (frame == frames.end()) {
    throw std::runtime_error(std::string("KITTI: frame ") + kDenseFrame +
                             " (images and sweep) of " + drive + " not found");
  }
  if (options.progress) *options.progress << "KITTI dense, frame " << frame->name << std::endl;
  DenseProtocolResult out;
  out.reference = kitti::buildAccumulatedReference(drive, kDenseFrame, calib, reference_params);
  const kitti::FrameData data = kitti::loadFrame(*frame, calib.camera);
  if (stereo_check_px > 0.0) {
    out.stereo_check = removeStereoOutliers(
        out.reference.depth, sgbmDisparity(data.left, data.right), calib.camera, stereo_check_px);
    out.reference.pixels = cv::countNonZero(out.reference.depth);
    out.reference.own_pixels = cv::countNonZero(out.reference.own & (out.reference.depth > 0.f));
  }
  LayoutScores<DepthMetrics>& layout = out.layout;
  layout.name = "dense";
  layout.items.push_back(frame->name);
  const FedSweep fed = fedSweep(data.cloud, options, calib);
  layout.fed_rings.push_back(fed.rings);
  LayoutAccumulator<DepthMetrics> acc;
  PmsRun pms;
  scoreDepthCase({data, fed.cloud, out.reference.depth, calib, layout.name, frame->name}, options,
                 pipelineRows(options, options.kitti_pms), pms, acc);
  layout.methods = acc.finish();
  const long center = static_cast<long>(kitti::frameIndex(kDenseFrame));
  layout.description =
      "KITTI drive 0009 frame " + std::to_string(center) + ", the full sweep (" +
      std::to_string(fed.rings) + " rings) fed, scored against the depth accumulated from sweeps " +
      std::to_string(center - reference_params.half_span) + "-" +
      std::to_string(center + reference_params.half_span) + " (" +
      std::to_string(out.reference.pixels) + " pixels, the frame's own sweep included; " +
      (reference_params.combine == kitti::AccumulationParams::Combine::kMajority
           ? "per pixel the depth most sweeps agree on)"
           : "per pixel the nearest point)") +
      (reference_params.keep_unverified ? ", points with no own point nearby kept" : "") +
      (stereo_check_px > 0.0
           ? ", kept where SGBM agrees within " + format("%g", stereo_check_px) + " px"
           : std::string()) +
      fed.note;
  return out;
}

}  // namespace lidar_stereo_fusion
