// kitti_runner end to end on a small synthetic KITTI drive written to a temp folder: output format,
// scoring, and a non-zero exit with a clear message for every kind of missing or corrupt input.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/io/kitti.h"
#include "tools/tool_runner.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

using test::RunResult;

/// The runner next to the test (plain CMake) or in the catkin devel space.
std::string runnerPath() { return test::toolPath("kitti_runner"); }

/// A synthetic drive "<root>/2011_01_01/drive_sync": 80x60 images, 3 frames, 16-laser sweeps in
/// KITTI storage order (laser by laser, azimuth from just past 0 through +-180 to just before 0) of
/// a sphere of radius 10 m around the sensor.
class SyntheticDrive {
 public:
  SyntheticDrive() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("lsf_runner_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    drive_ = root_ / "2011_01_01" / "drive_sync";
    for (const char* sub : {"image_02/data", "image_03/data", "velodyne_points/data"}) {
      fs::create_directories(drive_ / sub);
    }
    writeCalibration("");
    for (const std::string name : {"0000000000", "0000000001", "0000000002"}) {
      writeFrame(name, sweep(false));
    }
  }
  ~SyntheticDrive() { fs::remove_all(root_); }

  /// Writes the calibration, leaving out `drop_key`.
  void writeCalibration(const std::string& drop_key) const {
    std::ofstream cam(root_ / "2011_01_01" / "calib_cam_to_cam.txt");
    auto line = [&](std::ostream& out, const std::string& key, const std::string& values) {
      if (key != drop_key) out << key << ": " << values << "\n";
    };
    line(cam, "R_rect_00", "1 0 0 0 1 0 0 0 1");
    line(cam, "P_rect_02", "60 0 40 3 0 60 30 0 0 0 1 0");
    line(cam, "P_rect_03", "60 0 40 -27 0 60 30 0 0 0 1 0");  // B = 0.5 m
    line(cam, "S_rect_02", "80 60");
    std::ofstream velo(root_ / "2011_01_01" / "calib_velo_to_cam.txt");
    line(velo, "R", "0 -1 0 0 0 -1 1 0 0");  // x forward, y left, z up -> optical
    line(velo, "T", "0 0 0");
  }

  void writeFrame(const std::string& name, const LidarCloud& cloud) const {
    cv::Mat image(60, 80, CV_8UC3);
    std::mt19937 rng(std::stoi(name) + 1);
    std::uniform_int_distribution<int> value(0, 255);
    for (auto it = image.begin<cv::Vec3b>(); it != image.end<cv::Vec3b>(); ++it) {
      *it = cv::Vec3b(value(rng), value(rng), value(rng));
    }
    cv::imwrite((drive_ / "image_02/data" / (name + ".png")).string(), image);
    cv::imwrite((drive_ / "image_03/data" / (name + ".png")).string(), image);
    kitti::writeVelodyneBin((drive_ / "velodyne_points/data" / (name + ".bin")).string(), cloud);
  }

  /// What --deskew reads: calib_imu_to_velo.txt (IMU = Velodyne), the image and sweep stamps
  /// (the image at the sweep's forward instant) and a packet per frame moving at `vf` [m/s].
  void writeEgoMotion(double vf) const {
    std::ofstream(root_ / "2011_01_01" / "calib_imu_to_velo.txt")
        << "R: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\n";
    std::ofstream images(drive_ / "image_02/timestamps.txt");
    std::ofstream starts(drive_ / "velodyne_points/timestamps_start.txt");
    std::ofstream ends(drive_ / "velodyne_points/timestamps_end.txt");
    fs::create_directories(drive_ / "oxts/data");
    for (int i = 0; i < 3; ++i) {
      images << "2011-01-01 00:00:0" << i << ".050000000\n";
      starts << "2011-01-01 00:00:0" << i << ".000000000\n";
      ends << "2011-01-01 00:00:0" << i << ".100000000\n";
      std::ofstream(drive_ / "oxts/data" / ("000000000" + std::to_string(i) + ".txt"))
          << "49 8 100 0 0 0 0 0 " << vf << " 0 0 0 0 9.8 0 0 9.8 0 0 0 0 0 0 0.1 0.1 4 7 4 4 0\n";
    }
  }

  /// 16 lasers from +2 to -28 deg elevation; `behind` keeps only points with x < 0.
  static LidarCloud sweep(bool behind) {
    LidarCloud cloud;
    for (int laser = 0; laser < 16; ++laser) {
      const double elevation = (2.0 - 2.0 * laser) * M_PI / 180.0;
      for (int k = 0; k < 900; ++k) {
        const double azimuth = (0.2 + 0.4 * k) * M_PI / 180.0;  // 0.2 .. 359.8 deg
        LidarPoint p;
        p.x = static_cast<float>(10 * std::cos(elevation) * std::cos(azimuth));
        p.y = static_cast<float>(10 * std::cos(elevation) * std::sin(azimuth));
        p.z = static_cast<float>(10 * std::sin(elevation));
        if (behind && p.x >= 0) continue;
        cloud.push_back(p);
      }
    }
    return cloud;
  }

  RunResult run(const std::string& args) const {
    return test::runCommand(runnerPath() + " --kitti-raw " + drive_.string() + " " + args, root_);
  }

  fs::path drive() const { return drive_; }
  fs::path outDir() const { return root_ / "out"; }

 private:
  fs::path root_, drive_;
};

#define REQUIRE_RUNNER()                                                    \
  if (runnerPath().empty()) {                                               \
    GTEST_SKIP() << "kitti_runner is not built next to " << LSF_BINARY_DIR; \
  }

TEST(KittiRunner, WritesKittiDepthPngsOfImageSizeAndScoresAReference) {
  REQUIRE_RUNNER();
  SyntheticDrive drive;
  const std::string out = drive.outDir().string();
  const RunResult r = drive.run("--out " + out + " --method lidar_bi --save-vis");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string name : {"0000000000", "0000000001", "0000000002"}) {
    const cv::Mat raw = cv::imread(out + "/" + name + ".png", cv::IMREAD_UNCHANGED);
    ASSERT_EQ(raw.type(), CV_16UC1) << name;
    EXPECT_EQ(raw.size(), cv::Size(80, 60));
    // The sphere is 10 m from the sensor: depth along the optical axis is at most 10 m.
    const cv::Mat1f depth = kitti::readDepthPng(out + "/" + name + ".png");
    double max_depth = 0;
    cv::minMaxLoc(depth, nullptr, &max_depth);
    EXPECT_GT(cv::countNonZero(depth), 500);
    EXPECT_LE(max_depth, 10.0 + 1.0 / 256);
    EXPECT_TRUE(fs::exists(out + "/vis/" + name + "_disparity.png"));
    EXPECT_TRUE(fs::exists(out + "/vis/" + name + "_confidence.png"));
  }
  EXPECT_NE(r.out.find("| projection |"), std::string::npos) << r.out;  // timing summary
  EXPECT_NE(r.err.find("3/3"), std::string::npos) << r.err;             // progress bar

  // Score the output against itself: zero error on every covered pixel.
  const RunResult scored =
      drive.run("--out " + out + "_2 --method lidar_bi --reference " + out + " --frames 2");
  ASSERT_EQ(scored.status, 0) << scored.err;
  // The reference PNG is quantised to 1/256 m: errors below 2 mm, no bad pixel, full coverage.
  const auto mean = scored.out.find("| mean (2 frames) |");
  ASSERT_NE(mean, std::string::npos) << scored.out;
  double mae = -1, rmse = -1;
  ASSERT_EQ(std::sscanf(scored.out.c_str() + mean, "| mean (2 frames) | %lf | %lf |", &mae, &rmse),
            2);
  EXPECT_LE(mae, 2.0);
  EXPECT_LE(rmse, 2.0);
  const std::string line = scored.out.substr(mean, scored.out.find('\n', mean) - mean);
  EXPECT_NE(line.find("| 0.00 | 0.00 | 0.00 | 100.0 |"), std::string::npos) << line;
  fs::remove_all(out + "_2");
}

TEST(KittiRunner, FusedDefaultAndHoldoutRun) {
  REQUIRE_RUNNER();
  SyntheticDrive drive;
  const RunResult r = drive.run("--out " + drive.outDir().string() + " --holdout even --frames 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("fused_bi"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean (1 frames)"), std::string::npos) << r.out;
}

std::string fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The output never lands among the inputs: inside the drive (into image_02/data the depth PNGs
// would replace the images of the same names) or in the reference folder; nothing is written.
TEST(KittiRunner, AnOutputFolderAmongItsInputsIsRefused) {
  REQUIRE_RUNNER();
  SyntheticDrive drive;
  const fs::path images = drive.drive() / "image_02" / "data";
  const fs::path first = *fs::directory_iterator(images);
  const std::string before = fileBytes(first);
  const size_t files = std::distance(fs::directory_iterator(images), fs::directory_iterator());
  for (const std::string& out : {images.string(), images.string() + "/", drive.drive().string(),
                                 (drive.drive() / "new" / "depth").string()}) {
    const RunResult r = drive.run("--out " + out + " --method lidar_bi --frames 1");
    EXPECT_EQ(r.status, 1) << out;
    EXPECT_NE(r.err.find("is inside the drive (--kitti-raw)"), std::string::npos) << r.err;
  }
  EXPECT_EQ(fileBytes(first), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(images), fs::directory_iterator()), files);
  EXPECT_FALSE(fs::exists(drive.drive() / "new"));
  // the drive named with a trailing separator is the same drive
  const RunResult slash =
      test::runCommand(runnerPath() + " --kitti-raw " + drive.drive().string() + "/ --out " +
                           images.string() + " --method lidar_bi --frames 1",
                       drive.outDir().parent_path());
  EXPECT_EQ(slash.status, 1) << slash.err;
  EXPECT_NE(slash.err.find("is inside the drive (--kitti-raw)"), std::string::npos) << slash.err;
  // a symbolic link to the drive is the drive
  const fs::path link = drive.outDir().parent_path() / "drive_link";
  fs::create_directory_symlink(drive.drive(), link);
  const RunResult linked =
      drive.run("--out " + (link / "image_02" / "data").string() + " --method lidar_bi");
  EXPECT_EQ(linked.status, 1);
  EXPECT_EQ(fileBytes(first), before);
  fs::remove(link);
  // the reference folder
  const fs::path reference = drive.outDir().parent_path() / "reference";
  fs::create_directories(reference);
  const RunResult scored = drive.run("--out " + reference.string() + " --method lidar_bi " +
                                     "--reference " + reference.string());
  EXPECT_EQ(scored.status, 1);
  EXPECT_NE(scored.err.find("is inside the reference folder (--reference)"), std::string::npos)
      << scored.err;
}

TEST(KittiRunner, BadCommandLinesExitWith2AndHelpWith0) {
  REQUIRE_RUNNER();
  SyntheticDrive drive;
  EXPECT_EQ(drive.run("--out x --bogus").status, 2);
  EXPECT_EQ(drive.run("").status, 2);  // no --out
  EXPECT_EQ(drive.run("--out x --method magic").status, 2);
  EXPECT_EQ(drive.run("--out x --frames 0").status, 2);
  EXPECT_EQ(drive.run("--out x --holdout even --reference y").status, 2);
  const RunResult help = drive.run("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("Usage"), std::string::npos);
}

/// Runs into a fresh output folder; expects status 1 and `message` in stderr.
void expectFailure(const SyntheticDrive& drive, const std::string& message,
                   const std::string& extra = "--method lidar_bi") {
  const RunResult r = drive.run("--out " + drive.outDir().string() + " " + extra);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
}

TEST(KittiRunner, MissingOrCorruptInputExitsWith1AndSaysWhat) {
  REQUIRE_RUNNER();
  {
    SyntheticDrive drive;
    drive.writeCalibration("P_rect_03");
    expectFailure(drive, "'P_rect_03'");
  }
  {
    SyntheticDrive drive;
    std::ofstream(drive.drive() / "velodyne_points/data/0000000001.bin", std::ios::binary)
        << "seventeen bytes!!";
    expectFailure(drive, "multiple of 16");
  }
  {
    SyntheticDrive drive;
    cv::imwrite((drive.drive() / "image_03/data/0000000000.png").string(),
                cv::Mat(50, 80, CV_8UC3, cv::Scalar::all(0)));
    expectFailure(drive, "sizes differ");
  }
  {
    SyntheticDrive drive;
    std::ofstream(drive.drive() / "image_02/data/0000000002.png") << "not a png";
    expectFailure(drive, "cannot read image");
  }
  {
    SyntheticDrive drive;
    drive.writeFrame("0000000001", SyntheticDrive::sweep(true));
    expectFailure(drive, "0000000001");
    expectFailure(drive, "0000000001", "--method pms");
  }
  {
    SyntheticDrive drive;
    fs::create_directories(drive.outDir() / "ref");
    std::ofstream(drive.outDir() / "ref" / "0000000000.png") << "not a png";
    expectFailure(drive, "depth PNG",
                  "--method lidar_bi --reference " + (drive.outDir() / "ref").string());
  }
  {
    SyntheticDrive drive;
    fs::remove_all(drive.drive() / "image_03");
    expectFailure(drive, "no frame");
  }
}

// Issue 9, points 8 and 10: incomplete frames are named, a failing frame does not stop the run
// (exit 1 at the end), a wrong drive is named as such, an unwritable output folder fails first.
TEST(KittiRunner, SkippedAndFailedFramesAreNamedAndTheRunGoesOn) {
  REQUIRE_RUNNER();
  {
    SyntheticDrive drive;
    fs::remove(drive.drive() / "image_03/data/0000000001.png");
    const RunResult r = drive.run("--out " + drive.outDir().string() + " --method lidar_bi");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("skipped frame 0000000001: missing"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(drive.outDir() / "0000000000.png"));
    EXPECT_TRUE(fs::exists(drive.outDir() / "0000000002.png"));
  }
  {
    SyntheticDrive drive;
    std::ofstream(drive.drive() / "velodyne_points/data/0000000000.bin", std::ios::binary)
        << "seventeen bytes!!";
    const RunResult r = drive.run("--out " + drive.outDir().string() + " --method lidar_bi");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("frame 0000000000 failed"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1 of 3 frames failed: 0000000000"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(drive.outDir() / "0000000000.png"));
    EXPECT_TRUE(fs::exists(drive.outDir() / "0000000001.png")) << "the run stopped at frame 0";
    EXPECT_TRUE(fs::exists(drive.outDir() / "0000000002.png"));
  }
  {
    SyntheticDrive drive;
    const std::string command =
        runnerPath() + " --kitti-raw /nonexistent --out " + drive.outDir().string() + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[256];
    while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
    const int raw = pclose(pipe);
    EXPECT_EQ(WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, 1) << output;
    EXPECT_NE(output.find("/nonexistent is not a raw drive folder"), std::string::npos) << output;
    EXPECT_EQ(output.find("calib_cam_to_cam"), std::string::npos) << output;
  }
  {
    SyntheticDrive drive;  // /proc/self exists and takes no files, even as root
    const RunResult r = drive.run("--out /proc/self --method lidar_bi");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("cannot write into output folder /proc/self: "), std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("frames, method"), std::string::npos) << "failed only after starting";
  }
}

/// Mean of `a - b` over the columns [first, last] where both have depth.
double meanDifference(const cv::Mat1f& a, const cv::Mat1f& b, int first, int last) {
  double sum = 0.0;
  int n = 0;
  for (int v = 0; v < a.rows; ++v) {
    for (int u = first; u <= last; ++u) {
      if (a(v, u) > 0.f && b(v, u) > 0.f) sum += a(v, u) - b(v, u), ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

// --deskew: a standing rig changes nothing; at 10 m/s the sphere's left side (seen before the
// forward instant) comes nearer, its right side goes farther: a point az to the side, seen
// az / 360 * 0.1 s from the front, moves by delta = 10 m/s times that along x, and the sphere
// along a pixel's ray by delta cos^2(az) (8.2 cm and 6.2 cm at 29.5 deg, the image's edges); a
// frame without its packet is named, processed as measured and makes the exit status 1; a missing
// calib_imu_to_velo.txt fails the run.
TEST(KittiRunner, DeskewMovesTheSweepToTheImageInstant) {
  REQUIRE_RUNNER();
  SyntheticDrive drive;
  const std::string raw = drive.outDir().string() + "/raw",
                    still = drive.outDir().string() + "/still";
  ASSERT_EQ(drive.run("--out " + raw + " --method lidar_bi").status, 0);
  drive.writeEgoMotion(0.0);
  RunResult r = drive.run("--out " + still + " --method lidar_bi --deskew --photometric-check");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Deskew: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| all (3 frames) |"), std::string::npos) << r.out;
  const std::string frame0 = "/0000000000.png";
  EXPECT_EQ(cv::norm(kitti::readDepthPng(raw + frame0), kitti::readDepthPng(still + frame0),
                     cv::NORM_INF),
            0.0);

  drive.writeEgoMotion(10.0);
  const std::string moving = drive.outDir().string() + "/moving";
  r = drive.run("--out " + moving + " --method lidar_bi --deskew");
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat1f before = kitti::readDepthPng(raw + frame0);
  const cv::Mat1f after = kitti::readDepthPng(moving + frame0);
  // Column u looks az = atan((40 - u) / 60) to the left: 29.5 deg at u = 6, 34 deg at u = 74.
  EXPECT_NEAR(meanDifference(after, before, 4, 8), -0.062, 0.01);
  EXPECT_NEAR(meanDifference(after, before, 38, 42), 0.0, 0.01);
  EXPECT_NEAR(meanDifference(after, before, 72, 76), 0.062, 0.01);

  fs::remove(drive.drive() / "oxts/data/0000000001.txt");
  r = drive.run("--out " + moving + " --method lidar_bi --deskew");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("frame 0000000001 is not deskewed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 of 3 frames not deskewed (processed as measured): 0000000001"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::exists(moving + "/0000000001.png"));
  fs::remove(drive.drive().parent_path() / "calib_imu_to_velo.txt");
  r = drive.run("--out " + moving + " --method lidar_bi --deskew");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("calib_imu_to_velo.txt"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace lidar_stereo_fusion
