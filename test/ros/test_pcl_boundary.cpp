// Why the nodelet reads PointCloud2 with its own checked reader (conversions::cloudFromMsg) and
// not with PCL's conversion (issue 26; doc/libraries.md): a cloud whose declared layout needs
// more bytes than it carries is refused by this package, while PCL's fromROSMsg family has no
// such check and builds every declared point, reading past the end of the data. Shown safely:
// the data vector gets the capacity of the declared size (memory the test owns, so PCL's reads
// stay inside the allocation), filled with a marker that only a read past data.size() can see.
#include <cstring>
#include <string>

#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {
namespace {

namespace conv = conversions;

TEST(PclBoundary, CloudDeclaringMoreBytesThanItCarriesIsRefusedHereButPclReadsPastTheData) {
  constexpr int kCarried = 10, kDeclared = 1000;
  constexpr float kMarker = 4242.f;  // [m] what lies beyond the carried bytes
  LidarCloud points(kCarried);
  for (int i = 0; i < kCarried; ++i) points[i].x = static_cast<float>(i);
  std_msgs::Header header;
  header.frame_id = "velodyne";
  sensor_msgs::PointCloud2 msg = conv::cloudToMsg(points, header);  // x y z intensity ring time
  const std::size_t carried = msg.data.size();
  ASSERT_EQ(carried, static_cast<std::size_t>(kCarried) * msg.point_step);
  // The memory of the declared points, then cut back to the carried ones (capacity stays).
  msg.data.resize(static_cast<std::size_t>(kDeclared) * msg.point_step);
  for (std::size_t p = carried; p < msg.data.size(); p += msg.point_step) {
    std::memcpy(&msg.data[p], &kMarker, sizeof(kMarker));  // x of every point past the data
  }
  msg.data.resize(carried);
  msg.width = kDeclared;
  msg.row_step = msg.point_step * msg.width;
  ASSERT_GE(msg.data.capacity(), static_cast<std::size_t>(msg.row_step) * msg.height);

  // The declared layout does not fit the data: this package says so and reads nothing.
  EXPECT_GT(static_cast<std::size_t>(msg.row_step) * msg.height, msg.data.size());
  const std::string problem = conv::checkCloudLayout(msg);
  EXPECT_NE(problem.find("data has 220 bytes, row_step * height needs 22000"), std::string::npos)
      << problem;
  EXPECT_THROW(conv::cloudFromMsg(msg), conv::ConversionError);

  // PCL: no check; it makes all 1000 points, 990 of them from bytes past the data's end.
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::moveFromROSMsg(msg, cloud);  // moves the data (with its capacity) into PCL's cloud
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(kDeclared));
  EXPECT_EQ(cloud[kCarried - 1].x, kCarried - 1.f);
  EXPECT_EQ(cloud[kCarried].x, kMarker) << "PCL read the first point past the data";
  EXPECT_EQ(cloud[kDeclared - 1].x, kMarker);
}

}  // namespace
}  // namespace lidar_stereo_fusion
