#include "lib/image_input.h"

#include <cv_bridge/cv_bridge.h>
#include <image_transport/exception.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sift_hull {

ImageInput::ImageInput(image_transport::ImageTransport& transport, ros::NodeHandle nh,
                       const ros::NodeHandle& private_nh, const std::string& topic,
                       uint32_t queue_size, const std::string& transport_name) {
  try {
    image_sub_ = transport.subscribe(
        topic, queue_size, &ImageInput::onImage, this,
        image_transport::TransportHints(transport_name, ros::TransportHints(), private_nh));
  } catch (const image_transport::TransportLoadException& e) {
    if (transport_name != "compressed") {
      throw std::runtime_error("image transport '" + transport_name +
                               "' is not installed: " + e.what());
    }
    const std::string resolved = nh.resolveName(topic) + "/compressed";
    compressed_sub_ = nh.subscribe(resolved, queue_size, &ImageInput::onCompressed, this);
    ROS_INFO("no image_transport plugin for 'compressed': decoding %s here", resolved.c_str());
  }
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
