#pragma once

#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <string>

#include "sift_hull/Save.h"
#include "sift_hull/dataset.h"
#include "sift_hull/hull_stream.h"
#include "throttled_log.h"

namespace sift_hull {

/// Node settings besides the hull's own (HullStreamConfig).
struct HullNodeConfig {
  std::string world_frame = "world";
  /// Silhouettes waiting for their camera_info or their pose; when more wait, the oldest is
  /// dropped with an error (a pose that never arrives).
  int queue_size = 10;
  /// Subscribe `image` (8-bit colour or mono) instead of `silhouette`, and extract each
  /// silhouette by `recipe` (the Middlebury threshold, dilation and erosion).
  bool from_image = false;
  SilhouetteConfig recipe;
};

/// The hull node: silhouettes (mono8) with their camera_info, once tf knows the camera's pose in
/// the world frame, refine a visual hull; the results are published latched after every view.
class HullNode {
 public:
  /// Reads the private parameters (ros_params.h) and subscribes.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// With config structs, no parameter server needed.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh, HullNodeConfig node_config,
           HullStreamConfig hull_config);

 private:
  using Sync = message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo>;

  void onView(const sensor_msgs::ImageConstPtr& silhouette,
              const sensor_msgs::CameraInfoConstPtr& info);
  /// The view's mask: the silhouette message, or the one extracted from the image.
  cv::Mat maskOf(const sensor_msgs::ImageConstPtr& message, std::string* why_not) const;
  bool cameraOf(const sensor_msgs::Image& silhouette, const sensor_msgs::CameraInfo& info,
                PinholeCamera* camera);
  void carve(const std::string& name, const PinholeCamera& camera, const cv::Mat& mask);
  void publish(const ros::Time& stamp);
  void onPoseMissing(const sensor_msgs::ImageConstPtr& silhouette,
                     tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  bool reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool save(sift_hull::Save::Request& request, sift_hull::Save::Response& response);

  ros::NodeHandle nh_, private_nh_;
  HullNodeConfig config_;
  HullStream stream_;
  ThrottledLog log_;
  std::unique_ptr<octomap::OcTree> octree_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  message_filters::Subscriber<sensor_msgs::Image> silhouette_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  tf2_ros::MessageFilter<sensor_msgs::Image> pose_filter_;
  Sync sync_;
  ros::Publisher octomap_pub_, cloud_pub_, markers_pub_, mesh_pub_;
  ros::ServiceServer reset_srv_, save_srv_;
};

}  // namespace sift_hull
