#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>

#include <atomic>
#include <string>
#include <thread>

#include "lib/throttled_log.h"

namespace sift_hull {

/// tf2_ros::TransformListener's job (/tf and /tf_static into a tf2_ros::Buffer, on a thread and
/// callback queue of its own, the buffer cleared when the clock jumps back), with each transform
/// checked first, so that no message on /tf can stop the node or empty its buffer:
/// - a stamp within an hour of ros::Time's end is refused (tf2's cache adds its length to stamps
///   and throws, on the listener's thread, outside any catch);
/// - a /tf stamp more than kMaxAhead_s after the node's clock is refused (the cache would drop
///   every transform older than its length before that stamp, and the poses of current views
///   with it); not checked while the clock is zero (a bag's, before it starts);
/// - whatever the buffer still throws is caught.
/// Each refusal is logged (throttled per reason) and counted.
class TfListener {
 public:
  static constexpr double kMaxAhead_s = 2.0;

  TfListener(tf2_ros::Buffer* buffer, const std::string& log_prefix);
  ~TfListener();
  TfListener(const TfListener&) = delete;
  TfListener& operator=(const TfListener&) = delete;

  /// Transforms refused since the start.
  size_t refused() const { return refused_; }

  /// Why a transform stamped `stamp` received at `now` is refused; empty when it is not.
  static std::string refusal(const ros::Time& stamp, const ros::Time& now, bool is_static);

 private:
  void onMessage(const ros::MessageEvent<tf2_msgs::TFMessage const>& event, bool is_static);

  tf2_ros::Buffer* buffer_;
  const std::string log_prefix_;
  ThrottledLog log_;
  std::atomic<size_t> refused_{0};
  ros::Time last_update_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  ros::Subscriber tf_sub_, static_sub_;
  std::atomic<bool> running_{true};
  std::thread thread_;
};

}  // namespace sift_hull
