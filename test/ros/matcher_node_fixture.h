// The matcher node's rostest fixtures: a synthetic stereo pair rendered once per case, publishers
// of the inputs each mode subscribes, and the correspondences received. Every wait has a deadline.

#pragma once

#include <dynamic_reconfigure/Reconfigure.h>
#include <dynamic_reconfigure/client.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "cloud_checks.h"
#include "diagnostics_wait.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/MatcherConfig.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::kDeadline_s;
using test::waitFor;

inline sensor_msgs::Image bgrImage(const cv::Mat& image, const ros::Time& stamp,
                                   const std::string& frame) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  return ros_conversions::imageMessage(image, header);
}

inline PutativeMatches putativesOf(const sift_hull::Correspondences& message, cv::Size size) {
  PutativeMatches matches;
  matches.left_image_size = matches.right_image_size = size;
  for (const sift_hull::Correspondence& c : message.matches) {
    const int index = static_cast<int>(matches.matches.size());
    matches.left_keypoints.emplace_back(c.left.x, c.left.y, c.left.size, c.left.angle);
    matches.right_keypoints.emplace_back(c.right.x, c.right.y, c.right.size, c.right.angle);
    matches.matches.emplace_back(index, index, c.descriptor_distance);
  }
  return matches;
}

class MatcherNodeTest : public ::testing::Test {
 protected:
  /// Whether the node subscribes the inputs this test publishes.
  virtual bool inputsConnected() const {
    return left_pub_.getNumSubscribers() > 0 && right_pub_.getNumSubscribers() > 0;
  }
  virtual void advertise() {
    left_pub_ = nh_.advertise<sensor_msgs::Image>("left/image", 5);
    right_pub_ = nh_.advertise<sensor_msgs::Image>("right/image", 5);
  }

  void SetUp() override {
    SceneConfig config;
    config.width_px = 320;
    config.height_px = 240;
    left_ = renderSceneView(config, 0);
    right_ = renderSceneView(config, 1);
    advertise();
    sub_ = nh_.subscribe("correspondences", 5, &MatcherNodeTest::onCorrespondences, this);
    ASSERT_TRUE(waitFor([&] { return inputsConnected() && sub_.getNumPublishers() > 0; }))
        << "the matcher node did not connect";
  }

  ros::Time publishPair(const cv::Mat& left, const cv::Mat& right) {
    const ros::Time stamp = ros::Time::now();
    if (!left.empty()) left_pub_.publish(bgrImage(left, stamp, "left"));
    if (!right.empty()) right_pub_.publish(bgrImage(right, stamp, "right"));
    return stamp;
  }

  bool answeredAtLeast(const ros::Time& stamp) {
    return waitFor([&] { return last_ && last_->header.stamp >= stamp; });
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) {
    last_ = message;
    answered_.insert(message->header.stamp);
  }

  /// None of `stamps` was answered, however late (the node matches on worker threads).
  void expectNoneAnswered(const std::vector<ros::Time>& stamps) {
    for (const ros::Time& stamp : stamps) EXPECT_EQ(answered_.count(stamp), 0u) << stamp;
  }

  ros::NodeHandle nh_;
  ros::Publisher left_pub_, right_pub_, frame_pub_;
  ros::Subscriber sub_;
  RenderedView left_, right_;
  sift_hull::CorrespondencesConstPtr last_;
  std::set<ros::Time> answered_;
};

/// One image topic: each frame is matched with the one before it.
class FrameToFrameMatcherTest : public MatcherNodeTest {
 protected:
  bool inputsConnected() const override { return frame_pub_.getNumSubscribers() > 0; }
  void advertise() override { frame_pub_ = nh_.advertise<sensor_msgs::Image>("image", 5); }
};

}  // namespace
}  // namespace sift_hull
