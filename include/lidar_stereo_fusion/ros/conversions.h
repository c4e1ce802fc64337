// Conversions between ROS messages and the ROS-free core types. No algorithm here: only type
// conversion and the checks that belong where data enters (encodings, sizes, fields, NaN).
//
// Conventions (REP 103 / REP 118, stereo_image_proc):
//  * Images are rectified; the left view is the reference and its optical frame (x right, y down,
//    z forward) is the frame of every output.
//  * Disparity [px]: the core stores 0 for "no value"; stereo_msgs/DisparityImage marks it by a
//    value below min_disparity, which 0 is.
//  * Depth [m] in sensor_msgs/Image 32FC1, NaN = no value (REP 118).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <stereo_msgs/DisparityImage.h>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace conversions {

/// Thrown for input that cannot be converted; what() names the problem (not the topic: the caller
/// knows which topic the message came from).
class ConversionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A camera_info the conversion cannot use; `left` says whose (false: the right one's, or the
/// pair's), so that the message goes under that topic.
class CameraInfoError : public ConversionError {
 public:
  CameraInfoError(bool left, const std::string& what) : ConversionError(what), left(left) {}
  bool left;
};

/// True on a big-endian host (messages say their byte order in is_bigendian).
bool hostIsBigEndian();

/// Image encodings accepted for the stereo pair: bgra8 (ZED), rgba8, bgr8, rgb8, mono8.
const std::vector<std::string>& supportedImageEncodings();

/// Checks encoding, size and step of an image message without converting it; returns an empty
/// string when it is usable, else a description of the problem.
std::string checkImage(const sensor_msgs::Image& msg);

/// Converts one rectified image to what the core takes: BGR CV_8UC3 for colour encodings, CV_8UC1
/// for mono8 (always a copy that owns its pixels). Throws ConversionError on an unsupported
/// encoding or a malformed message.
cv::Mat imageToCore(const sensor_msgs::ImageConstPtr& msg);

/// Decodes a sensor_msgs/CompressedImage (png or jpeg, as compressed_image_transport and most
/// recorders write it) into the sensor_msgs/Image the synchroniser and imageToCore take, with the
/// same header: bgr8 for colour (the codecs' channel order, whatever the format string says the
/// camera published), bgra8 with an alpha channel, mono8 for grey. Decoded by cv_bridge
/// (cv_bridge::toCvCopy), so the node and the bag tools decode alike without an image_transport
/// plugin. Throws ConversionError naming the problem: no data, a compressedDepth image (a depth
/// map, not a camera image), bytes no codec reads, or a bit depth other than 8.
sensor_msgs::ImagePtr decompressImage(const sensor_msgs::CompressedImage& msg);

/// Converts a stereo pair; the two results have the same type. A mono8 view with a colour view:
/// both are matched as grey (the colour one converted with OpenCV's BGR2GRAY), since a grey view
/// cannot be matched against colours; `note` (if given) then says so, naming both encodings, and
/// is empty otherwise. Throws ConversionError when either image is unusable or the sizes differ.
void stereoPairToCore(const sensor_msgs::ImageConstPtr& left,
                      const sensor_msgs::ImageConstPtr& right, cv::Mat& left_out,
                      cv::Mat& right_out, std::string* note = nullptr);

/// Rectified stereo camera from the two camera_infos: fx, fy, cx, cy from the left projection
/// matrix P; baseline B [m] = |Tx_right - Tx_left| / fx with Tx = P[3] (so both sign conventions,
/// Tx = -fx * B as in ROS and +fx * B as some drivers write it, work). Throws ConversionError
/// CameraInfoError (naming "left"/"right" and the field) when P is zero, the focal lengths
/// disagree or B is 0.
StereoCamera stereoCameraFromInfo(const sensor_msgs::CameraInfo& left,
                                  const sensor_msgs::CameraInfo& right);

/// Where a sweep keeps each point's measurement time. One rule for every driver: the first field
/// present in this order is read, and LidarPoint::time is the offset [s] of the point's time from
/// the cloud's header stamp, whatever instant of the sweep the stamp is (start, end or middle).
enum class PointTimeField {
  kNone,         ///< no per-point time: every point has the stamp's time
  kTime,         ///< `time`: s relative to the stamp (velodyne_pointcloud, float32)
  kT,            ///< `t`: ns relative to the stamp (Ouster, uint32)
  kOffsetTime,   ///< `offset_time`: ns relative to the stamp (Livox, uint32)
  kTimestamp,    ///< `timestamp`: absolute s (Hesai, float64)
  kTimeSecNsec,  ///< `time_sec` + `time_nsec`: absolute s and ns (Luminar, uint32 each)
};

/// The field's name as in the message ("time", "t", ..., "time_sec + time_nsec", "none").
const char* pointTimeFieldName(PointTimeField field);

/// [s] A point time farther than this from the stamp is implausible by default (two revolutions of
/// a 10 Hz LiDAR): a wrong unit or a broken clock, not a measurement.
constexpr double kDefaultMaxPointTime = 0.2;

/// Result of converting a sensor_msgs/PointCloud2 sweep.
struct CloudConversion {
  LidarCloud cloud;       ///< finite points only, in the cloud's frame [m]
  bool has_ring = false;  ///< the message had a `ring` field (points carry it)
  bool has_time = false;  ///< the message had a per-point time field (time_field)
  PointTimeField time_field = PointTimeField::kNone;
  /// Points whose time was NaN / inf or farther than max_point_time from the stamp: they keep
  /// time 0 (the stamp's), and the caller names them; bad_time_example is the first such value.
  int bad_times = 0;
  double bad_time_example = 0.0;
  int total_points = 0;  ///< width * height of the message
  int non_finite = 0;    ///< points skipped because x, y or z was NaN / inf
  int implausible = 0;   ///< points skipped because |x|, |y| or |z| > kMaxCoordinate
};

/// [m] A coordinate beyond this is no LiDAR return (e.g. 1e38 in a corrupt sweep): dropped,
/// counted.
constexpr double kMaxCoordinate = 1e4;

/// Checks the layout of a cloud without reading its points: x, y, z fields present as FLOAT32 or
/// FLOAT64, the fields read (x, y, z, intensity, ring, the time fields) with count 1 and a numeric
/// type, point_step / row_step / data size consistent, little-endian. Returns an empty string when
/// usable, else the problem.
std::string checkCloudLayout(const sensor_msgs::PointCloud2& msg);

/// The part of checkCloudLayout about the fields' types: x, y, z FLOAT32 or FLOAT64, the fields
/// read with count 1 and a known numeric type. Empty when usable, else the problem.
std::string checkCloudFieldTypes(const sensor_msgs::PointCloud2& msg);

/// Reads a sweep as velodyne_pointcloud publishes it (x, y, z, intensity, ring, time) or any other
/// layout with at least x, y, z. `intensity`, `ring` and the time fields (PointTimeField) are
/// optional and may have any numeric datatype (float32/64, (u)int8/16/32). Non-finite points are
/// skipped and counted; point times beyond `max_point_time` [s] of the stamp, or NaN, are counted
/// in bad_times and not used. Throws ConversionError when checkCloudLayout() fails.
CloudConversion cloudFromMsg(const sensor_msgs::PointCloud2& msg,
                             double max_point_time = kDefaultMaxPointTime);

/// Writes a core cloud as PointCloud2 with float32 x, y, z, intensity, uint16 ring, float32 time
/// (the velodyne_pointcloud layout). Used by tests and tools.
sensor_msgs::PointCloud2 cloudToMsg(const LidarCloud& cloud, const std_msgs::Header& header);

/// Disparity [px] (0 = no value) as stereo_msgs/DisparityImage filled as stereo_image_proc does:
/// f = fx [px], T = baseline [m], min/max_disparity = the configured search range [min_search,
/// max_search] (values outside it, NaN included, become 0 = no value), delta_d = the nominal
/// sub-pixel step, valid_window = bounding box of valid pixels.
stereo_msgs::DisparityImagePtr disparityToMsg(const cv::Mat1f& disparity,
                                              const std_msgs::Header& header,
                                              const StereoCamera& camera, double min_search,
                                              double max_search);

/// Depth [m] (0 = no value) as a 32FC1 image with NaN = no value (REP 118). Values beyond
/// `max_depth` (> 0) are also NaN.
sensor_msgs::ImagePtr depthToMsg(const cv::Mat1f& depth, const std_msgs::Header& header,
                                 double max_depth = 0.0);

/// A BGR8 picture (CV_8UC3) as a bgr8 image (copied).
sensor_msgs::ImagePtr bgrImageToMsg(const cv::Mat& image, const std_msgs::Header& header);

/// A float map as a 32FC1 image, unchanged (e.g. the LiDAR prior: disparity [px], 0 = empty).
sensor_msgs::ImagePtr floatImageToMsg(const cv::Mat1f& image, const std_msgs::Header& header);

/// The coloured points of `depth` [m] and the left `image` (makeOrganizedCloud: left optical
/// frame, every `stride`-th row and column) as PointCloud2 with float32 x, y, z and rgb packed as
/// in PCL / depth_image_proc (0x00RRGGBB in the bytes of a float32). Organised (height x width as
/// the grid, point (u, v) at row v, column u) like stereo_image_proc's points2; NaN x, y, z = no
/// value, so is_dense is false unless every point has one. Written in one pass
/// (packOrganizedCloud). Throws like makeOrganizedCloud.
sensor_msgs::PointCloud2Ptr organizedCloudToMsg(const cv::Mat1f& depth, const cv::Mat& image,
                                                const StereoCamera& camera, int stride,
                                                const std_msgs::Header& header);

}  // namespace conversions
}  // namespace lidar_stereo_fusion
