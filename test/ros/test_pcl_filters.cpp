// rostest (test/ros/pcl_filters.test, issue 26): the fusion with pcl_ros's CropBox (negative, on
// the sweep) and VoxelGrid (on points2) in one nodelet manager, on a KITTI bag written by
// kitti_to_bag at test time and published frame by frame:
//  * the filtered sweep holds exactly the returns outside the box, and so does the fusion's input
//    (stats points_in_cloud); no return inside the box reaches the projection: the prior's
//    largest disparity is at most that of the nearest return outside the box, below what the
//    returns inside the box would give;
//  * a voxel cloud comes with every points2 (same stamp, to PCL's microseconds), with fewer points.
// It also prints what each filter costs per frame: the same PCL calls as the nodelets (conversion
// in, filter, conversion out) timed here, beside the fusion's total_ms of that frame.
// Missing data fails under CI=true and skips otherwise.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <pcl/filters/crop_box.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "child_process.h"
#include "data/data_guard.h"
#include "kitti_bag_util.h"
#include "lidar_stereo_fusion/FusionStats.h"

namespace fs = std::filesystem;
namespace lt = lidar_stereo_fusion::test;
using Cloud = sensor_msgs::PointCloud2;

namespace {

const std::vector<std::string> kFrames = {"0000000000", "0000000005", "0000000010"};
const Eigen::Vector3f kBoxMin(-20, -30, -5), kBoxMax(12, 30, 5);  ///< [m] as in pcl_filters.test
constexpr double kLeaf = 0.2;                                     ///< [m] as in pcl_filters.test
constexpr double kTimeout = 240.0;  ///< [s] for one frame's outputs (a few s on two cores)

/// Messages by stamp, with the wall time they came.
template <typename M>
struct Inbox {
  std::map<ros::Time, std::pair<boost::shared_ptr<const M>, double>> messages;
};

class Collector {
 public:
  explicit Collector(ros::NodeHandle& nh) {
    subs_ = {sub(nh, "velodyne_points_self_filtered", filtered_), sub(nh, "points2", points_),
             sub(nh, "points2_voxel", voxel_), sub(nh, "lidar_disparity", prior_),
             sub(nh, "stats", stats_)};
  }
  bool connected() const {
    for (const auto& s : subs_) {
      if (s.getNumPublishers() == 0) return false;
    }
    return true;
  }
  /// Waits until `ready()` holds (under the lock) or `timeout` s pass; returns ready().
  bool waitFor(const std::function<bool()>& ready, double timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout), ready);
  }
  /// The message of `box` stamped `t` to the microsecond (pcl_conversions keeps microseconds).
  template <typename M>
  const std::pair<boost::shared_ptr<const M>, double>* at(const Inbox<M>& box, ros::Time t) const {
    for (const auto& kv : box.messages) {
      if (std::abs((kv.first - t).toNSec()) < 1000) return &kv.second;
    }
    return nullptr;
  }
  std::mutex mutex_;
  Inbox<Cloud> filtered_, points_, voxel_;
  Inbox<sensor_msgs::Image> prior_;
  Inbox<lidar_stereo_fusion::FusionStats> stats_;

 private:
  template <typename M>
  ros::Subscriber sub(ros::NodeHandle& nh, const std::string& topic, Inbox<M>& box) {
    return nh.subscribe<M>(topic, 5, [this, &box](const boost::shared_ptr<const M>& m) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        box.messages[m->header.stamp] = {m, ros::WallTime::now().toSec()};
      }
      cv_.notify_all();
    });
  }
  std::condition_variable cv_;
  std::vector<ros::Subscriber> subs_;
};

bool insideBox(float x, float y, float z) {  // pcl::CropBox's test (bounds included)
  return x >= kBoxMin.x() && y >= kBoxMin.y() && z >= kBoxMin.z() && x <= kBoxMax.x() &&
         y <= kBoxMax.y() && z <= kBoxMax.z();
}

/// Returns outside the box, and the largest disparity [px] of returns outside / inside the box
/// that land in the left image.
struct Expected {
  int outside = 0;
  double max_disparity_outside = 0, max_disparity_inside = 0;
};

Expected expectedOf(const Cloud& sweep, const Eigen::Isometry3d& T_cam_velo,
                    const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right) {
  const double fx = left.P[0], cx = left.P[2], fy = left.P[5], cy = left.P[6];
  const double baseline = std::abs(right.P[3] - left.P[3]) / fx;
  Expected e;
  sensor_msgs::PointCloud2ConstIterator<float> x(sweep, "x"), y(sweep, "y"), z(sweep, "z");
  for (; x != x.end(); ++x, ++y, ++z) {
    if (!std::isfinite(*x) || !std::isfinite(*y) || !std::isfinite(*z)) continue;
    const bool inside = insideBox(*x, *y, *z);
    if (!inside) ++e.outside;
    const Eigen::Vector3d p = T_cam_velo * Eigen::Vector3d(*x, *y, *z);
    if (p.z() <= 0) continue;
    const double u = fx * p.x() / p.z() + cx, v = fy * p.y() / p.z() + cy;
    if (u < 0 || v < 0 || u >= left.width || v >= left.height) continue;
    double& max = inside ? e.max_disparity_inside : e.max_disparity_outside;
    max = std::max(max, fx * baseline / p.z());
  }
  return e;
}

/// Wall time [ms] of `work` (one run).
double msOf(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

/// What the CropBox / VoxelGrid nodelets do per message: ROS -> PCL, filter, PCL -> ROS [ms].
double cropBoxMs(const Cloud& in) {
  return msOf([&] {
    auto pcl_in = std::make_shared<pcl::PCLPointCloud2>();
    pcl_conversions::toPCL(in, *pcl_in);
    pcl::CropBox<pcl::PCLPointCloud2> box;
    box.setMin(Eigen::Vector4f(kBoxMin.x(), kBoxMin.y(), kBoxMin.z(), 1));
    box.setMax(Eigen::Vector4f(kBoxMax.x(), kBoxMax.y(), kBoxMax.z(), 1));
    box.setNegative(true);
    box.setInputCloud(pcl_in);
    pcl::PCLPointCloud2 out;
    box.filter(out);
    Cloud msg;
    pcl_conversions::moveFromPCL(out, msg);
  });
}

double voxelGridMs(const Cloud& in) {
  return msOf([&] {
    auto pcl_in = std::make_shared<pcl::PCLPointCloud2>();
    pcl_conversions::toPCL(in, *pcl_in);
    pcl::VoxelGrid<pcl::PCLPointCloud2> grid;
    grid.setLeafSize(kLeaf, kLeaf, kLeaf);
    grid.setInputCloud(pcl_in);
    pcl::PCLPointCloud2 out;
    grid.filter(out);
    Cloud msg;
    pcl_conversions::moveFromPCL(out, msg);
  });
}

int finitePoints(const Cloud& cloud) {
  int n = 0;
  sensor_msgs::PointCloud2ConstIterator<float> z(cloud, "z");
  for (; z != z.end(); ++z) n += std::isfinite(*z) ? 1 : 0;
  return n;
}

}  // namespace

TEST(PclFilters, CropBoxAndVoxelGridInTheFusionsManager) {
  LSF_REQUIRE_DATA(std::string(lt::kKittiDate) + "/" + lt::kKittiDrive);
  const std::string scratch = lt::scratchDir("test_pcl_filters");
  const std::string bag_path = scratch + "/frames.bag";
  fs::remove(bag_path);
  const auto [status, output] =
      lt::runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " +
                     lt::makeSubsetDrive(scratch, kFrames) + " --out " + bag_path);
  ASSERT_EQ(status, 0) << output;
  rosbag::Bag bag;
  auto topics = lt::readBag(bag_path, bag);
  ASSERT_EQ(topics["/stereo/left/image_rect_color"].size(), kFrames.size());
  const auto tf_static = topics["/tf_static"].front().instantiate<tf2_msgs::TFMessage>();
  const Eigen::Isometry3d T_cam_velo = tf2::transformToEigen(tf_static->transforms.at(0)).inverse();

  ros::NodeHandle nh, fusion_nh("fusion");
  Collector got(fusion_nh);
  ros::Publisher tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
  tf_pub.publish(tf_static);
  std::map<std::string, ros::Publisher> in;
  for (const char* t : {"/stereo/left/image_rect_color", "/stereo/right/image_rect_color"}) {
    in[t] = nh.advertise<sensor_msgs::Image>(t, 5);
  }
  for (const char* t : {"/stereo/left/camera_info", "/stereo/right/camera_info"}) {
    in[t] = nh.advertise<sensor_msgs::CameraInfo>(t, 5);
  }
  in["/velodyne_points"] = nh.advertise<Cloud>("/velodyne_points", 5);
  // Lazy all the way: our subscriptions make the fusion subscribe to the CropBox's output, the
  // CropBox to the sweep, the VoxelGrid to points2.
  auto connected = [&] {
    for (const auto& kv : in) {
      if (kv.second.getNumSubscribers() == 0) return false;
    }
    return got.connected();
  };
  ASSERT_TRUE(lt::waitFor(60.0, connected)) << "the fusion and the pcl_ros filters did not connect";

  std::printf(
      "frame       | CropBox in test [ms] | VoxelGrid in test [ms] | fusion total_ms | "
      "sweep -> filtered [ms] | points2 -> voxel [ms] | points2 / voxel points\n");
  ros::Time last_stamp;
  for (size_t i = 0; i < kFrames.size(); ++i) {
    SCOPED_TRACE("frame " + kFrames[i]);
    const auto sweep = topics["/velodyne_points"][i].instantiate<Cloud>();
    const auto left_info =
        topics["/stereo/left/camera_info"][i].instantiate<sensor_msgs::CameraInfo>();
    const auto right_info =
        topics["/stereo/right/camera_info"][i].instantiate<sensor_msgs::CameraInfo>();
    const auto left = topics["/stereo/left/image_rect_color"][i].instantiate<sensor_msgs::Image>();
    const Expected expected = expectedOf(*sweep, T_cam_velo, *left_info, *right_info);
    ASSERT_GT(expected.max_disparity_inside, expected.max_disparity_outside + 1.0)
        << "the box must hold returns nearer than any outside it, or the test shows nothing";

    // The sweep first; the images once the filtered sweep is out (the fusion then has it).
    const double sent = ros::WallTime::now().toSec();
    in["/velodyne_points"].publish(sweep);
    ASSERT_TRUE(got.waitFor([&] { return got.at(got.filtered_, sweep->header.stamp); }, 60.0));
    in["/stereo/left/camera_info"].publish(left_info);
    in["/stereo/right/camera_info"].publish(right_info);
    in["/stereo/right/image_rect_color"].publish(
        topics["/stereo/right/image_rect_color"][i].instantiate<sensor_msgs::Image>());
    in["/stereo/left/image_rect_color"].publish(left);
    const ros::Time t = left->header.stamp;
    last_stamp = t;
    ASSERT_TRUE(got.waitFor(
        [&] {
          return got.at(got.stats_, t) && got.at(got.prior_, t) && got.at(got.points_, t) &&
                 got.at(got.voxel_, t);
        },
        kTimeout))
        << "not every output came";

    std::lock_guard<std::mutex> lock(got.mutex_);
    const auto& filtered = *got.at(got.filtered_, sweep->header.stamp);
    EXPECT_EQ(static_cast<int>(filtered.first->width * filtered.first->height), expected.outside);
    const auto& stats = *got.at(got.stats_, t)->first;
    EXPECT_EQ(stats.points_in_cloud, expected.outside)
        << "the fusion's input is the filtered sweep";
    double lo = 0, hi = 0;
    cv::minMaxLoc(cv_bridge::toCvShare(got.at(got.prior_, t)->first)->image, &lo, &hi);
    EXPECT_GT(hi, 0.0);
    EXPECT_LE(hi, expected.max_disparity_outside * (1 + 1e-4))
        << "a return inside the box reached the prior (inside ones give up to "
        << expected.max_disparity_inside << " px)";
    const auto& points = *got.at(got.points_, t);
    const auto& voxel = *got.at(got.voxel_, t);
    const int points_n = finitePoints(*points.first);
    const int voxel_n = static_cast<int>(voxel.first->width * voxel.first->height);
    EXPECT_GT(voxel_n, 0);
    EXPECT_LT(voxel_n, points_n);
    EXPECT_EQ(voxel.first->header.frame_id, points.first->header.frame_id);
    std::printf("%s  | %20.1f | %22.1f | %15.1f | %22.1f | %21.1f | %d / %d\n", kFrames[i].c_str(),
                cropBoxMs(*sweep), voxelGridMs(*points.first), stats.total_ms,
                (filtered.second - sent) * 1e3, (voxel.second - points.second) * 1e3, points_n,
                voxel_n);
  }
  // The node processed each frame once, and no extra cloud follows the last frame's (a topic
  // delivers in order: one of an earlier frame would have come before).
  EXPECT_FALSE(got.waitFor(
      [&] {
        return got.points_.messages.size() > kFrames.size() ||
               got.voxel_.messages.size() > kFrames.size();
      },
      1.0))
      << "an extra points2 or voxel cloud";
  std::lock_guard<std::mutex> lock(got.mutex_);
  EXPECT_EQ(got.at(got.stats_, last_stamp)->first->processed_frames, kFrames.size());
  EXPECT_EQ(got.points_.messages.size(), kFrames.size());
  EXPECT_EQ(got.voxel_.messages.size(), got.points_.messages.size())
      << "the voxel cloud comes at the rate of points2";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_pcl_filters");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
