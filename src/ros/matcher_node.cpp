#include "matcher_node.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "conversions.h"
#include "ros_params.h"
#include "sift_hull/match_drawing.h"

namespace sift_hull {
namespace {

constexpr double kThrottle_s = 5.0;

std::vector<std::unique_ptr<MatchFilter>> makeFilters(const MatcherSettings& settings) {
  std::vector<std::unique_ptr<MatchFilter>> filters;
  for (const std::string& spec : settings.node.filters) {
    if (spec.find("epipolar") != std::string::npos) {
      throw std::invalid_argument("filter '" + spec +
                                  "': the epipolar filter needs calibration, which matcher_node "
                                  "does not take yet");
    }
    filters.push_back(makeFilter(spec, settings.filters));
  }
  if (filters.empty()) throw std::invalid_argument("~filters names no filter");
  return filters;
}

std::string settingsJson(const MatcherSettings& settings) {
  const FilterConfigs& f = settings.filters;
  const nlohmann::json json = {
      {"ratio", settings.matching.ratio},
      {"max_descriptor_distance", std::isfinite(settings.matching.max_descriptor_distance)
                                      ? nlohmann::json(settings.matching.max_descriptor_distance)
                                      : nlohmann::json(nullptr)},
      {"cross_check", settings.matching.cross_check},
      {"gsc_max_histogram_distance", f.gsc.max_histogram_distance},
      {"ransac_max_epipolar_px", f.ransac.max_epipolar_px},
      {"magsac_max_epipolar_px", f.magsac.max_epipolar_px},
      {"gms_threshold_factor", f.gms.threshold_factor}};
  return json.dump();
}

/// An 8-bit image as BGR or grey, or empty with `why_not` set.
cv::Mat imageOf(const sensor_msgs::ImageConstPtr& image, std::string* why_not) {
  namespace enc = sensor_msgs::image_encodings;
  if (image->width == 0 || image->height == 0) {
    *why_not = "the image is empty";
    return {};
  }
  if (!enc::isColor(image->encoding) && !enc::isMono(image->encoding)) {
    *why_not = "encoding '" + image->encoding + "' is neither colour nor mono";
    return {};
  }
  if (enc::bitDepth(image->encoding) != 8) {
    *why_not = "encoding '" + image->encoding + "' is not 8 bits per channel";
    return {};
  }
  try {
    return cv_bridge::toCvShare(image, enc::isMono(image->encoding) ? "mono8" : "bgr8")->image;
  } catch (const cv_bridge::Exception& e) {
    *why_not = e.what();
    return {};
  }
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

}  // namespace

MatcherNode::MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : MatcherNode(nh, private_nh, ros_params::readMatcherSettings(private_nh)) {}

MatcherNode::MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh, MatcherSettings settings)
    : nh_(nh),
      private_nh_(private_nh),
      settings_(std::move(settings)),
      filters_(makeFilters(settings_)),
      settings_json_(settingsJson(settings_)),
      transport_(nh_),
      left_sub_(transport_, "left/image", settings_.node.queue_size),
      right_sub_(transport_, "right/image", settings_.node.queue_size) {
  const int queue = settings_.node.queue_size;
  if (settings_.node.approximate_sync) {
    approximate_sync_ = std::make_unique<ApproximateSync>(
        message_filters::sync_policies::ApproximateTime<Image, Image>(queue), left_sub_,
        right_sub_);
    approximate_sync_->registerCallback(&MatcherNode::onPair, this);
  } else {
    exact_sync_ = std::make_unique<ExactSync>(
        message_filters::sync_policies::ExactTime<Image, Image>(queue), left_sub_, right_sub_);
    exact_sync_->registerCallback(&MatcherNode::onPair, this);
  }
  correspondences_pub_ = nh_.advertise<sift_hull::Correspondences>("correspondences", queue);
  matches_image_pub_ = transport_.advertise("matches_image", 1);
}

void MatcherNode::onPair(const sensor_msgs::ImageConstPtr& left,
                         const sensor_msgs::ImageConstPtr& right) {
  std::string why_not;
  const cv::Mat left_image = imageOf(left, &why_not);
  const cv::Mat right_image = left_image.empty() ? cv::Mat() : imageOf(right, &why_not);
  if (left_image.empty() || right_image.empty()) {
    ROS_ERROR_THROTTLE(kThrottle_s, "matcher: pair at %.3f ignored: %s", left->header.stamp.toSec(),
                       why_not.c_str());
    return;
  }
  const PutativeMatches matches =
      matchImages(left_image, right_image, settings_.sift, settings_.matching);
  if (matches.left_keypoints.size() < 2 || matches.right_keypoints.size() < 2) {
    ROS_ERROR_THROTTLE(kThrottle_s, "matcher: pair at %.3f has %zu and %zu keypoints, too few",
                       left->header.stamp.toSec(), matches.left_keypoints.size(),
                       matches.right_keypoints.size());
    return;
  }
  std::vector<FilterResult> results;
  for (const auto& filter : filters_) results.push_back(filter->apply(matches));
  correspondences_pub_.publish(message(*left, *right, matches, results));
  if (matches_image_pub_.getNumSubscribers() > 0) {
    const cv::Mat drawing = drawMatchDecisions(left_image, right_image, matches, results.front());
    matches_image_pub_.publish(cv_bridge::CvImage(left->header, "bgr8", drawing).toImageMsg());
  }
}

sift_hull::Correspondences MatcherNode::message(const sensor_msgs::Image& left,
                                                const sensor_msgs::Image& right,
                                                const PutativeMatches& matches,
                                                const std::vector<FilterResult>& results) const {
  sift_hull::Correspondences out;
  out.header = left.header;
  out.right_header = right.header;
  for (const auto& filter : filters_) out.filters.push_back(filter->name());
  out.filter_settings = settings_json_;
  for (size_t m = 0; m < matches.matches.size(); ++m) {
    const cv::DMatch& match = matches.matches[m];
    sift_hull::Correspondence correspondence;
    correspondence.left = keypointMessage(matches.left_keypoints[match.queryIdx]);
    correspondence.right = keypointMessage(matches.right_keypoints[match.trainIdx]);
    correspondence.descriptor_distance = match.distance;
    correspondence.gsc_score = std::nanf("");
    for (size_t f = 0; f < results.size(); ++f) {
      if (results[f].keep[m]) correspondence.kept_by |= 1u << f;
      if (out.filters[f] == "gsc") correspondence.gsc_score = results[f].score[m];
    }
    out.matches.push_back(correspondence);
  }
  return out;
}

}  // namespace sift_hull
