#include "lib/tf_listener.h"

#include <cstdint>
#include <limits>
#include <sstream>

namespace sift_hull {

TfListener::TfListener(tf2_ros::Buffer* buffer, const std::string& log_prefix)
    : buffer_(buffer), log_prefix_(log_prefix) {
  nh_.setCallbackQueue(&queue_);
  using Event = ros::MessageEvent<tf2_msgs::TFMessage const>;
  tf_sub_ = nh_.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100,
      boost::function<void(const Event&)>([this](const Event& e) { onMessage(e, false); }));
  static_sub_ = nh_.subscribe<tf2_msgs::TFMessage>(
      "/tf_static", 100,
      boost::function<void(const Event&)>([this](const Event& e) { onMessage(e, true); }));
  thread_ = std::thread([this] {
    while (running_ && nh_.ok()) queue_.callAvailable(ros::WallDuration(0.1));
  });
}

TfListener::~TfListener() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
  tf_sub_.shutdown();
  static_sub_.shutdown();
}

std::string TfListener::refusal(const ros::Time& stamp, const ros::Time& now, bool is_static) {
  constexpr uint32_t kLastSecond = std::numeric_limits<uint32_t>::max() - 3600;
  if (stamp.sec > kLastSecond) {
    return "stamped within an hour of the largest time ros::Time holds";
  }
  if (!is_static && !now.isZero() && stamp.toSec() > now.toSec() + kMaxAhead_s) {
    std::ostringstream why;  // no value in it: one throttled message however far ahead
    why << "stamped more than " << kMaxAhead_s
        << " s after this node's clock: are the clocks synchronised?";
    return why.str();
  }
  return "";
}

void TfListener::onMessage(const ros::MessageEvent<tf2_msgs::TFMessage const>& event,
                           bool is_static) {
  const ros::Time now = ros::Time::now();
  if (now < last_update_) {  // as tf2_ros::TransformListener: a bag played again
    ROS_WARN("%sthe clock jumped back: tf's buffer is cleared", log_prefix_.c_str());
    buffer_->clear();
  }
  last_update_ = now;
  const std::string& authority = event.getPublisherName();
  for (const geometry_msgs::TransformStamped& transform : event.getMessage()->transforms) {
    std::string why = refusal(transform.header.stamp, now, is_static);
    if (why.empty()) {
      try {
        buffer_->setTransform(transform, authority, is_static);
        continue;
      } catch (const std::exception& e) {
        why = e.what();
      }
    }
    ++refused_;
    log_.error(log_prefix_ + "tf transform from '" + transform.header.frame_id + "' to '" +
                   transform.child_frame_id + "' refused: ",
               why);
  }
}

}  // namespace sift_hull
