#include "lib/image_input.h"

#include <cv_bridge/cv_bridge.h>
#include <image_transport/exception.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sift_hull {

ImageInput::ImageInput(image_transport::ImageTransport& transport, ros::NodeHandle nh,
                       const ros::NodeHandle& private_nh, const std::string& topic,
                       uint32_t queue_size, const std::string& transport_name)
    : transport_(transport),
      nh_(nh),
      private_nh_(private_nh),
      resolved_topic_(nh.resolveName(topic)),
      queue_size_(queue_size),
      transport_name_(transport_name) {}

void ImageInput::subscribe() {
  try {
    image_sub_ = transport_.subscribe(
        resolved_topic_, queue_size_, &ImageInput::onImage, this,
        image_transport::TransportHints(transport_name_, ros::TransportHints(), private_nh_));
  } catch (const image_transport::TransportLoadException& e) {
    if (transport_name_ != "compressed") {
      throw std::runtime_error("image transport '" + transport_name_ +
                               "' is not installed: " + e.what());
    }
    const std::string resolved = resolved_topic_ + "/compressed";
    compressed_sub_ = nh_.subscribe(resolved, queue_size_, &ImageInput::onCompressed, this);
    ROS_INFO("no image_transport plugin for 'compressed': decoding %s here", resolved.c_str());
  }
}

void ImageInput::unsubscribe() {
  image_sub_.shutdown();
  compressed_sub_.shutdown();
}

void ImageInput::onCompressed(const sensor_msgs::CompressedImageConstPtr& compressed) {
  const cv::Mat decoded =
      compressed->data.empty() ? cv::Mat() : cv::imdecode(compressed->data, cv::IMREAD_UNCHANGED);
  cv::Mat image = decoded;
  if (decoded.channels() == 4) cv::cvtColor(decoded, image, cv::COLOR_BGRA2BGR);
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    log_.error("image ignored: ", "cannot decode an 8-bit image from the compressed '" +
                                      compressed->format + "' message on " +
                                      compressed_sub_.getTopic());
    return;
  }
  const std::string encoding = image.channels() == 1 ? "mono8" : "bgr8";
  signalMessage(cv_bridge::CvImage(compressed->header, encoding, image).toImageMsg());
}

}  // namespace sift_hull
