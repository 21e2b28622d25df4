#pragma once

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <Eigen/Geometry>
#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <string>

#include "lib/pose_waits.h"

namespace sift_hull {

/// The one owner of the wait for a camera's pose: an image paired with its camera_info waits in a
/// tf2_ros::MessageFilter until tf has the pose of the image's frame in the world frame at its
/// stamp, and leaves with it (T_W_C, looked up once); or it is dropped, said why and counted once:
/// tf gave up on it (empty frame id, older than tf keeps, the filter's queue full), a view of the
/// same frame id and stamp is waiting already, or its pose did not come within `timeout_s` of wall
/// time (reported by a wall timer when it expires; should the
/// pose still come, the view is not taken).
class PoseWait {
 public:
  using Posed =
      std::function<void(const sensor_msgs::ImageConstPtr&, const sensor_msgs::CameraInfoConstPtr&,
                         const Eigen::Isometry3d& T_W_C)>;
  /// A view left out: its frame id and why.
  using Dropped = std::function<void(const std::string& frame, const std::string& why)>;

  /// `queue_size` images wait at most; timeout_s <= 0: no timeout.
  PoseWait(ros::NodeHandle nh, tf2_ros::Buffer* tf, std::string world_frame, uint32_t queue_size,
           double timeout_s, Posed posed, Dropped dropped);

  void add(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info);
  /// Drops every view waiting for its pose (~reset): none of them comes out later. Returns how
  /// many there were.
  size_t clear();
  /// Views dropped without a pose (timed out, given up by tf, or a duplicate of a waiting view's
  /// frame id and stamp), each counted once.
  size_t dropped() const { return dropped_; }

 private:
  void onPose(const sensor_msgs::ImageConstPtr& image);
  void onFailure(const sensor_msgs::ImageConstPtr& image,
                 tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void expire();
  sensor_msgs::CameraInfoConstPtr takeInfo(const sensor_msgs::Image* image);

  tf2_ros::Buffer* tf_;
  const std::string world_frame_;
  const double timeout_s_;
  Posed posed_;
  Dropped dropped_view_;
  PoseWaits waits_;
  std::mutex infos_mutex_;
  /// The camera_info of each image in the filter (the filter's queue bounds it).
  std::map<const sensor_msgs::Image*, sensor_msgs::CameraInfoConstPtr> infos_;
  std::atomic<size_t> dropped_{0};
  tf2_ros::MessageFilter<sensor_msgs::Image> filter_;
  ros::WallTimer timer_;
};

}  // namespace sift_hull
