// One image input of the live node (left or right image_rect_color), as a message_filters source
// of sensor_msgs/Image for the image-set synchroniser. Subscribed through image_transport with
// ~image_transport (raw by default) when that transport's plugin is installed; for `compressed`
// without the plugin (Debian packages none), or a topic remapped to a .../compressed name, the
// input subscribes to sensor_msgs/CompressedImage itself and decodes each message with cv_bridge
// (conversions::decompressImage, as bag_runner does). A transport that is not installed never
// aborts the node: it is named with the installed ones, and raw images are used.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <image_transport/image_transport.h>
#include <message_filters/simple_filter.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

namespace lidar_stereo_fusion {

/// How the image inputs are subscribed.
struct TransportChoice {
  std::string requested = "raw";   ///< ~image_transport
  std::string transport = "raw";   ///< the image_transport plugin used (when not decoding)
  bool decode_compressed = false;  ///< sensor_msgs/CompressedImage on <topic>/compressed, decoded
  std::string note;                ///< said once at start-up ("" = nothing to say)
  bool error = false;              ///< the note is an error: the request could not be followed
};

/// The choice for `requested` given the installed plugins `loadable` (as
/// ImageTransport::getLoadableTransports() lists them: "image_transport/raw", ...; the prefix may
/// be missing). Pure.
TransportChoice chooseTransport(const std::string& requested,
                                const std::vector<std::string>& loadable);

/// ~image_transport (read as image_transport's TransportHints read it) and the installed plugins
/// of `nh`'s ImageTransport.
TransportChoice chooseTransport(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

class ImageInput : public message_filters::SimpleFilter<sensor_msgs::Image> {
 public:
  /// Called with the input's (relative) name, the problem and the message stamp when a message
  /// cannot be decoded (the message is dropped).
  using ErrorCallback = std::function<void(const std::string& name, const std::string& problem,
                                           const ros::Time& stamp)>;
  ImageInput(std::string name, ErrorCallback on_error)
      : name_(std::move(name)), on_error_(std::move(on_error)) {}

  /// The topic this input reads with `choice`: the resolved name, or with /compressed appended
  /// when decoding; a resolved name that already ends in /compressed is read as it is.
  static std::string subscribedTopic(const ros::NodeHandle& nh, const std::string& name,
                                     const TransportChoice& choice);

  /// Subscribes with `choice`; a plugin that fails to load falls back as chooseTransport would
  /// (reported through the error callback), never throws.
  void subscribe(image_transport::ImageTransport& it, ros::NodeHandle& nh,
                 const ros::NodeHandle& pnh, uint32_t queue_size, const TransportChoice& choice);
  void unsubscribe();
  uint32_t getNumPublishers() const;

 private:
  void imageCb(const sensor_msgs::ImageConstPtr& msg) { signalMessage(msg); }
  void compressedCb(const sensor_msgs::CompressedImageConstPtr& msg);

  std::string name_;
  ErrorCallback on_error_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber compressed_sub_;
};

}  // namespace lidar_stereo_fusion
