#pragma once

#include <ros/console.h>
#include <ros/time.h>

#include <map>
#include <mutex>
#include <string>

namespace sift_hull {

/// Errors throttled per reason rather than per call site: a second, different problem is reported
/// at once, the same problem again only after `period_s`.
class ThrottledLog {
 public:
  explicit ThrottledLog(double period_s = 5.0) : period_(period_s) {}

  /// Logs `prefix + reason` unless the same reason was logged less than the period ago.
  void error(const std::string& prefix, const std::string& reason) {
    const ros::WallTime now = ros::WallTime::now();
    std::lock_guard<std::mutex> lock(mutex_);
    auto found = last_.find(reason);
    if (found != last_.end() && now - found->second < period_) return;
    last_[reason] = now;
    ROS_ERROR("%s%s", prefix.c_str(), reason.c_str());
  }

 private:
  ros::WallDuration period_;
  std::mutex mutex_;
  std::map<std::string, ros::WallTime> last_;
};

}  // namespace sift_hull
