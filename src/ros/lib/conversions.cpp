#include "lib/conversions.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/limits.h"
#include "sift_hull/settings_json.h"

namespace sift_hull {
namespace ros_conversions {

bool holdsPixels(const sensor_msgs::Image& image, size_t bytes_per_pixel, std::string* why_not) {
  const std::string size = std::to_string(image.width) + "x" + std::to_string(image.height);
  if (image.width == 0 || image.height == 0) {
    *why_not = "the image is empty (" + size + ")";
    return false;
  }
  if (image.width > limits::kMaxImageSidePx || image.height > limits::kMaxImageSidePx) {
    *why_not = "the image is " + size + ", wider or higher than " +
               std::to_string(limits::kMaxImageSidePx) + " pixels";
    return false;
  }
  // Every factor is below 2^32, so no product of two wraps in size_t.
  const size_t pixels = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  if (pixels > limits::kMaxDecodedImagePixels) {
    *why_not = "the image is " + size + ", more than " +
               std::to_string(limits::kMaxDecodedImagePixels) + " pixels";
    return false;
  }
  const size_t row_bytes = static_cast<size_t>(image.width) * bytes_per_pixel;
  const size_t needed = static_cast<size_t>(image.step) * static_cast<size_t>(image.height);
  if (image.step < row_bytes || image.data.size() < needed) {
    *why_not = "the image data (" + std::to_string(image.data.size()) + " bytes, step " +
               std::to_string(image.step) + ") does not hold " + size + " pixels of " +
               std::to_string(bytes_per_pixel) + " bytes";
    return false;
  }
  return true;
}

bool withinPixelLimit(const sensor_msgs::Image& image, size_t max_pixels, std::string* why_not) {
  const size_t pixels = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  if (pixels <= max_pixels) return true;
  *why_not = "the image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
             " = " + std::to_string(pixels) + " pixels, more than max_image_pixels (" +
             std::to_string(max_pixels) + ")";
  return false;
}

cv::Mat maskFromImage(const sensor_msgs::Image& image, std::string* why_not) {
  // 8UC1 is what cv_bridge gives a uint8 array without an encoding: the same bytes as mono8.
  if (image.encoding != "mono8" && image.encoding != "8UC1") {
    *why_not = "silhouette encoding is '" + image.encoding + "', expected mono8 (or 8UC1)";
    return {};
  }
  if (!holdsPixels(image, 1, why_not)) {
    *why_not = "silhouette: " + *why_not;
    return {};
  }
  const cv::Mat view(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.data.data()),
                     image.step);
  return view.clone();
}

bool holdsEightBitImage(const sensor_msgs::Image& image, std::string* why_not) {
  namespace enc = sensor_msgs::image_encodings;
  if (!enc::isColor(image.encoding) && !enc::isMono(image.encoding)) {
    *why_not = "encoding '" + image.encoding + "' is neither colour nor mono";
    return false;
  }
  if (enc::bitDepth(image.encoding) != 8) {
    *why_not = "encoding '" + image.encoding + "' is not 8 bits per channel";
    return false;
  }
  return holdsPixels(image, static_cast<size_t>(enc::numChannels(image.encoding)), why_not);
}

cv::Mat eightBitImage(const sensor_msgs::ImageConstPtr& image, std::string* why_not) {
  namespace enc = sensor_msgs::image_encodings;
  if (!holdsEightBitImage(*image, why_not)) return {};
  try {
    return cv_bridge::toCvShare(image, enc::isMono(image->encoding) ? "mono8" : "bgr8")->image;
  } catch (const cv_bridge::Exception& e) {
    *why_not = e.what();
    return {};
  }
}

cv::Mat alphaMask(const sensor_msgs::ImageConstPtr& image) {
  namespace enc = sensor_msgs::image_encodings;
  if (!enc::hasAlpha(image->encoding) || enc::bitDepth(image->encoding) != 8) return {};
  std::string why_not;
  if (!holdsEightBitImage(*image, &why_not)) return {};
  cv::Mat alpha;
  try {
    cv::extractChannel(cv_bridge::toCvShare(image, "bgra8")->image, alpha, 3);
  } catch (const cv_bridge::Exception&) {
    return {};
  }
  double low = 0.0, high = 0.0;
  cv::minMaxLoc(alpha, &low, &high);
  if (!(low < high)) return {};  // a constant alpha says nothing about the object
  cv::Mat mask;
  cv::compare(alpha, 128, mask, cv::CMP_GE);
  return mask;
}

sensor_msgs::Image imageMessage(const cv::Mat& image, const std_msgs::Header& header) {
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3) {
    throw std::invalid_argument("imageMessage: expected an 8-bit grey or BGR image");
  }
  sensor_msgs::Image message;
  message.header = header;
  message.width = image.cols;
  message.height = image.rows;
  message.encoding = image.channels() == 1 ? "mono8" : "bgr8";
  message.step = static_cast<uint32_t>(image.cols * image.elemSize());
  message.data.resize(static_cast<size_t>(message.step) * image.rows);
  for (int row = 0; row < image.rows; ++row) {
    std::copy(image.ptr<uint8_t>(row), image.ptr<uint8_t>(row) + message.step,
              message.data.begin() + static_cast<size_t>(row) * message.step);
  }
  return message;
}

sensor_msgs::CameraInfo cameraInfoMessage(const PinholeCamera& camera, cv::Size size,
                                          const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = size.width;
  info.height = size.height;
  const LensDistortion& d = camera.distortion();
  info.distortion_model = d.fisheye      ? "equidistant"
                          : d.rational() ? "rational_polynomial"
                                         : "plumb_bob";
  info.D = {d.k1, d.k2, d.p1, d.p2, d.k3};
  if (d.rational()) info.D.insert(info.D.end(), {d.k4, d.k5, d.k6});
  if (d.fisheye) info.D = {d.k1, d.k2, d.k3, d.k4};
  for (int i = 0; i < 9; ++i) {
    info.K[i] = camera.K()(i / 3, i % 3);
    info.R[i] = i % 4 == 0 ? 1.0 : 0.0;
    info.P[i / 3 * 4 + i % 3] = camera.K()(i / 3, i % 3);
  }
  return info;
}

geometry_msgs::TransformStamped cameraPoseMessage(const PinholeCamera& camera,
                                                  const std::string& world_frame,
                                                  const std::string& camera_frame,
                                                  const ros::Time& stamp) {
  if (camera.improper()) {
    throw std::invalid_argument(
        "camera '" + camera_frame +
        "' lives in a mirrored world frame (det R = -1): it has no tf pose (no rotation gives "
        "it); mirror the calibration's world frame (negate one axis of every P) first");
  }
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  T_W_C.linear() = camera.R().transpose();
  T_W_C.translation() = camera.centre();
  geometry_msgs::TransformStamped pose = tf2::eigenToTransform(T_W_C);
  pose.header.stamp = stamp;
  pose.header.frame_id = world_frame;
  pose.child_frame_id = camera_frame;
  return pose;
}

std_msgs::ColorRGBA colour(float r, float g, float b) {
  std_msgs::ColorRGBA c;
  c.r = r, c.g = g, c.b = b, c.a = 1.0f;
  return c;
}

visualization_msgs::Marker marker(const std_msgs::Header& header, const std::string& ns,
                                  int32_t type, const std_msgs::ColorRGBA& colour) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color = colour;
  return m;
}

visualization_msgs::Marker meshMarker(const TriangleMesh& mesh, const std_msgs::Header& header) {
  visualization_msgs::Marker marker = ros_conversions::marker(
      header, "hull_mesh", visualization_msgs::Marker::TRIANGLE_LIST, colour(0.8f, 0.8f, 0.8f));
  marker.points.reserve(3 * mesh.faces.size());
  for (const Eigen::Vector3i& face : mesh.faces) {
    for (int corner = 0; corner < 3; ++corner) {
      const Eigen::Vector3f& vertex = mesh.vertices_W[face[corner]];
      geometry_msgs::Point point;
      point.x = vertex.x(), point.y = vertex.y(), point.z = vertex.z();
      marker.points.push_back(point);
    }
  }
  return marker;
}

sift_hull::Keypoint keypointMessage(const cv::KeyPoint& keypoint) {
  sift_hull::Keypoint message;
  message.x = keypoint.pt.x;
  message.y = keypoint.pt.y;
  message.size = keypoint.size;
  message.angle = keypoint.angle;
  message.response = keypoint.response;
  message.octave = keypoint.octave;
  return message;
}

sift_hull::Correspondences correspondencesMessage(const std_msgs::Header& left_header,
                                                  const std_msgs::Header& right_header,
                                                  const std::vector<std::string>& filter_names,
                                                  const std::string& settings_json,
                                                  const PutativeMatches& matches,
                                                  const std::vector<FilterResult>& results) {
  if (filter_names.size() != results.size() || results.size() > 32) {
    throw std::invalid_argument("correspondencesMessage: " + std::to_string(filter_names.size()) +
                                " filter names for " + std::to_string(results.size()) +
                                " results (at most 32)");
  }
  for (const FilterResult& result : results) {
    if (result.keep.size() != matches.matches.size() ||
        result.score.size() != matches.matches.size()) {
      throw std::invalid_argument(
          "correspondencesMessage: a filter result has not one entry "
          "per match");
    }
  }
  sift_hull::Correspondences out;
  out.header = left_header;
  out.right_header = right_header;
  out.filters = filter_names;
  out.filter_settings = settings_json;
  const auto gsc = std::find(filter_names.begin(), filter_names.end(), "gsc");
  const FilterResult* gsc_result =
      gsc == filter_names.end() ? nullptr : &results[gsc - filter_names.begin()];
  for (size_t m = 0; m < matches.matches.size(); ++m) {
    sift_hull::Correspondence correspondence;
    correspondence.left = keypointMessage(matches.left(m));
    correspondence.right = keypointMessage(matches.right(m));
    correspondence.descriptor_distance = matches.matches[m].distance;
    correspondence.gsc_score = gsc_result ? gsc_result->score[m] : std::nanf("");
    for (size_t f = 0; f < results.size(); ++f) {
      if (results[f].keep[m]) correspondence.kept_by |= 1u << f;
    }
    out.matches.push_back(correspondence);
  }
  return out;
}

std::string settingsJson(const MatchConfig& matching, const FilterConfigs& filters) {
  nlohmann::json json = sift_hull::settingsJson(settingsOf<MatchConfig>(), matching);
  json.update(sift_hull::settingsJson(settingsOf<FilterConfigs>(), filters));
  return json.dump();
}

}  // namespace ros_conversions
}  // namespace sift_hull
