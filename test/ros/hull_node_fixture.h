#pragma once

// The hull node's rostests' fixture: 8 synthetic views of a sphere with their poses in tf, the
// silhouette and camera_info publishers and the octomap_binary and occupied_cells subscribers.

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "common/octomap_volume.h"
#include "lib/conversions.h"
#include "ros_wait.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace test {

constexpr int kViews = 8;

/// The hull rostests' scene: kViews views of the sphere from around it, 320x240.
inline SceneConfig sphereSceneConfig() {
  SceneConfig config;
  config.shape = "sphere";
  config.views = kViews;
  config.layout = "sphere";
  config.width_px = 320;
  config.height_px = 240;
  return config;
}

inline std::vector<RenderedView> sphereViews() { return renderScene(sphereSceneConfig()); }

inline std::string frameOf(int view) { return "camera_" + std::to_string(view); }

class HullNodeTest : public ::testing::Test {
 protected:
  /// Whether the node extracts silhouettes from images (hull_from_image.test).
  virtual bool fromImage() const { return false; }
  /// The scene the case publishes.
  virtual SceneConfig sceneConfig() const { return sphereSceneConfig(); }

  void SetUp() override {
    views_ = renderScene(sceneConfig());
    std::vector<geometry_msgs::TransformStamped> poses;
    for (int v = 0; v < static_cast<int>(views_.size()); ++v) {
      poses.push_back(
          ros_conversions::cameraPoseMessage(views_[v].view.camera, "world", frameOf(v), {}));
    }
    // A pose that is not a number: tf refuses it, so views in this frame never get a pose.
    poses.push_back(
        ros_conversions::cameraPoseMessage(views_[0].view.camera, "world", "camera_nan", {}));
    poses.back().transform.translation.x = std::nan("");
    tf_.sendTransform(poses);
    silhouette_pub_ = nh_.advertise<sensor_msgs::Image>(fromImage() ? "image" : "silhouette", 20);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", 20);
    octomap_sub_ = nh_.subscribe("octomap_binary", 20, &HullNodeTest::onOctomap, this);
    cloud_sub_ = nh_.subscribe("occupied_cells", 20, &HullNodeTest::onCloud, this);
    rosout_sub_ = nh_.subscribe("/rosout", 100, &HullNodeTest::onLog, this);
    ASSERT_TRUE(waitFor([&] {
      return silhouette_pub_.getNumSubscribers() > 0 && info_pub_.getNumSubscribers() > 0;
    })) << "the hull node did not subscribe";
    resetHull();  // each case starts from no hull, whatever ran before it
    // The node's log reaches this test only once its /rosout link to the test is up, which can
    // be after the first errors of a case: until the line of a reset arrives, reset again.
    ASSERT_TRUE(waitFor([&] {
      std_srvs::Empty again;
      ros::service::call("/hull/reset", again);
      return waitFor([&] { return heard_reset_.load(); }, 0.2);
    })) << "no line of the hull node reached this test on /rosout";
  }

  /// Calls ~reset and waits for the empty map it publishes.
  void resetHull() {
    std_srvs::Empty reset;
    ASSERT_TRUE(ros::service::waitForService("/hull/reset", ros::Duration(kDeadline_s)));
    ASSERT_TRUE(ros::service::call("/hull/reset", reset));
    ASSERT_TRUE(waitFor([&] { return last_octomap_ && occupiedVolume(*last_octomap_) == 0.0; }))
        << "no empty map after ~reset";
  }

  /// Publishes every view; the stamp of the last.
  ros::Time publishAllViews() {
    ros::Time last;
    for (int v = 0; v < static_cast<int>(views_.size()); ++v) last = publishView(v);
    return last;
  }

  /// Publishes view `v` with `stamp` (default: now); `change` may spoil the messages first.
  ros::Time publishView(
      int v, const std::function<void(sensor_msgs::Image*, sensor_msgs::CameraInfo*)>& change = {},
      const ros::Time& stamp = {}) {
    std_msgs::Header header;
    header.stamp = stamp.isZero() ? ros::Time::now() : stamp;
    header.frame_id = frameOf(v);
    sensor_msgs::Image image =
        ros_conversions::imageMessage(fromImage() ? views_[v].image : views_[v].mask, header);
    sensor_msgs::CameraInfo info =
        ros_conversions::cameraInfoMessage(views_[v].view.camera, views_[v].mask.size(), header);
    if (change) change(&image, &info);
    info_pub_.publish(info);
    silhouette_pub_.publish(image);
    ros::WallDuration(0.05).sleep();
    return header.stamp;
  }

  bool octomapStampedAtLeast(const ros::Time& stamp) {
    return waitFor([&] { return last_octomap_ && last_octomap_->header.stamp >= stamp; });
  }

  /// Whether the node logs an error containing every one of `parts` within the deadline.
  bool loggedError(const std::vector<std::string>& parts) {
    return waitFor([&] {
      std::lock_guard<std::mutex> lock(errors_mutex_);
      for (const std::string& error : errors_) {
        bool all = true;
        for (const std::string& part : parts) all = all && error.find(part) != std::string::npos;
        if (all) return true;
      }
      return false;
    });
  }

  void onLog(const rosgraph_msgs::LogConstPtr& log) {
    if (log->msg.rfind("hull: reset", 0) == 0) heard_reset_ = true;
    std::lock_guard<std::mutex> lock(errors_mutex_);
    if (log->level == rosgraph_msgs::Log::ERROR) errors_.push_back(log->msg);
  }
  void onOctomap(const sift_hull::OctomapConstPtr& message) { last_octomap_ = message; }
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& message) { last_cloud_ = message; }

  ros::NodeHandle nh_;
  tf2_ros::StaticTransformBroadcaster tf_;
  ros::Publisher silhouette_pub_, info_pub_;
  ros::Subscriber octomap_sub_, cloud_sub_, rosout_sub_;
  std::mutex errors_mutex_;
  std::vector<std::string> errors_;       ///< the errors on /rosout since SetUp
  std::atomic<bool> heard_reset_{false};  ///< a reset's line arrived on /rosout
  std::vector<RenderedView> views_;
  sift_hull::OctomapConstPtr last_octomap_;
  sensor_msgs::PointCloud2ConstPtr last_cloud_;
};

}  // namespace test
}  // namespace sift_hull
