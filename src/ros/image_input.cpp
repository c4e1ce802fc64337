#include "lidar_stereo_fusion/ros/image_input.h"

#include <algorithm>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

namespace {

const std::string kCompressed = "compressed";

/// "image_transport/raw" -> "raw".
std::string shortName(const std::string& transport) {
  const std::string prefix = "image_transport/";
  return transport.rfind(prefix, 0) == 0 ? transport.substr(prefix.size()) : transport;
}

/// Hints for `transport`. TransportHints reads ~image_transport over its argument, so a transport
/// other than the requested one (a fallback) is given under a parameter name nobody sets.
image_transport::TransportHints hintsFor(const std::string& transport,
                                         const TransportChoice& choice,
                                         const ros::NodeHandle& pnh) {
  return image_transport::TransportHints(
      transport, ros::TransportHints(), pnh,
      transport == choice.requested ? "image_transport" : "image_transport_fallback_unset");
}

bool endsWith(const std::string& text, const std::string& end) {
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

}  // namespace

TransportChoice chooseTransport(const std::string& requested,
                                const std::vector<std::string>& loadable) {
  TransportChoice c;
  c.requested = requested.empty() ? "raw" : requested;
  std::vector<std::string> installed;
  for (const auto& t : loadable) installed.push_back(shortName(t));
  std::string names;
  for (const auto& t : installed) names += (names.empty() ? "" : ", ") + t;
  if (names.empty()) names = "none";
  const bool is_installed =
      std::find(installed.begin(), installed.end(), c.requested) != installed.end();
  if (c.requested == "raw" || is_installed) {
    c.transport = c.requested;
    if (c.requested != "raw") c.note = "image inputs through image_transport's " + c.requested;
    return c;
  }
  if (c.requested == kCompressed) {
    c.decode_compressed = true;
    c.note = "image_transport has no 'compressed' plugin here (installed: " + names +
             "); the image inputs subscribe to sensor_msgs/CompressedImage on <topic>/compressed "
             "and decode it with cv_bridge";
    return c;
  }
  c.transport = "raw";
  c.error = true;
  c.note = "~image_transport '" + c.requested + "' is not installed (installed: " + names +
           "; 'compressed' is decoded by this node without a plugin): subscribing to raw images";
  return c;
}

TransportChoice chooseTransport(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  // TransportHints reads ~image_transport, with "raw" when it is not set.
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh);
  std::vector<std::string> loadable;
  try {
    loadable = image_transport::ImageTransport(nh).getLoadableTransports();
  } catch (const std::exception&) {  // no plugin list at all: raw is built in
    loadable = {"image_transport/raw"};
  }
  return chooseTransport(hints.getTransport(), loadable);
}

std::string ImageInput::subscribedTopic(const ros::NodeHandle& nh, const std::string& name,
                                        const TransportChoice& choice) {
  const std::string resolved = nh.resolveName(name);
  if (endsWith(resolved, "/" + kCompressed) || !choice.decode_compressed) return resolved;
  return resolved + "/" + kCompressed;
}

void ImageInput::subscribe(image_transport::ImageTransport& it, ros::NodeHandle& nh,
                           const ros::NodeHandle& pnh, uint32_t queue_size,
                           const TransportChoice& choice) {
  const std::string topic = subscribedTopic(nh, name_, choice);
  if (choice.decode_compressed || endsWith(topic, "/" + kCompressed)) {
    compressed_sub_ = nh.subscribe(topic, queue_size, &ImageInput::compressedCb, this);
    return;
  }
  try {
    image_sub_ = it.subscribe(name_, queue_size, &ImageInput::imageCb, this,
                              hintsFor(choice.transport, choice, pnh));
  } catch (const std::exception& e) {  // a declared plugin that does not load
    on_error_(name_,
              "image_transport '" + choice.transport + "' failed to load (" + e.what() +
                  (choice.transport == kCompressed
                       ? "); decoding sensor_msgs/CompressedImage on " + topic + "/compressed"
                       : "); subscribing to raw images"),
              ros::Time());
    if (choice.transport == kCompressed) {
      compressed_sub_ =
          nh.subscribe(topic + "/" + kCompressed, queue_size, &ImageInput::compressedCb, this);
    } else {
      image_sub_ =
          it.subscribe(name_, queue_size, &ImageInput::imageCb, this, hintsFor("raw", choice, pnh));
    }
  }
}

void ImageInput::unsubscribe() {
  image_sub_.shutdown();
  compressed_sub_.shutdown();
}

uint32_t ImageInput::getNumPublishers() const {
  return compressed_sub_ ? compressed_sub_.getNumPublishers() : image_sub_.getNumPublishers();
}

void ImageInput::compressedCb(const sensor_msgs::CompressedImageConstPtr& msg) {
  sensor_msgs::ImagePtr image;
  try {
    image = conversions::decompressImage(*msg);
  } catch (const conversions::ConversionError& e) {
    on_error_(name_, e.what(), msg->header.stamp);
    return;
  }
  signalMessage(image);
}

}  // namespace lidar_stereo_fusion
