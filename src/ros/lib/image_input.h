#pragma once

#include <image_transport/image_transport.h>
#include <message_filters/simple_filter.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <string>

#include "lib/throttled_log.h"

namespace sift_hull {

/// The images of a topic as a message_filters source, through image_transport with the given
/// transport ("raw", "compressed", ...). Debian ships only image_transport's raw plugin: for
/// "compressed" without a plugin, TOPIC/compressed (sensor_msgs/CompressedImage) is subscribed and
/// decoded here, so compressed bags and cameras work either way.
class ImageInput : public message_filters::SimpleFilter<sensor_msgs::Image> {
 public:
  /// `private_nh` is the node's (a nodelet's own, not the manager's), where image_transport
  /// would look for ~image_transport. Subscribes nothing until subscribe().
  ImageInput(image_transport::ImageTransport& transport, ros::NodeHandle nh,
             const ros::NodeHandle& private_nh, const std::string& topic, uint32_t queue_size,
             const std::string& transport_name);

  /// Subscribes the topic (again after unsubscribe). Throws std::runtime_error for a transport
  /// that no plugin provides.
  void subscribe();
  /// Stops the subscription; messages on their way are dropped.
  void unsubscribe();
  /// The image topic, resolved (remappings applied).
  const std::string& resolvedTopic() const { return resolved_topic_; }

 private:
  void onImage(const sensor_msgs::ImageConstPtr& image) { signalMessage(image); }
  void onCompressed(const sensor_msgs::CompressedImageConstPtr& compressed);

  image_transport::ImageTransport& transport_;
  ros::NodeHandle nh_, private_nh_;
  std::string resolved_topic_;
  uint32_t queue_size_;
  std::string transport_name_;
  ThrottledLog log_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber compressed_sub_;
};

}  // namespace sift_hull
