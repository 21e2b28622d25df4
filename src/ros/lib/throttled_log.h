#pragma once

#include <ros/console.h>
#include <ros/time.h>

#include <algorithm>
#include <iterator>
#include <map>
#include <mutex>
#include <string>

namespace sift_hull {

/// Errors throttled per message rather than per call site: a second, different problem is
/// reported at once, the same message again only after `period_s`. It remembers at most
/// kMaxMessages messages (those older than the period are forgotten first), so messages that
/// carry changing values cannot grow it without bound.
class ThrottledLog {
 public:
  explicit ThrottledLog(double period_s = 5.0) : period_(period_s) {}

  static constexpr size_t kMaxMessages = 256;

  /// Logs `prefix + reason` unless the same message was logged less than the period ago;
  /// returns whether it logged.
  bool error(const std::string& prefix, const std::string& reason) {
    const std::string message = prefix + reason;
    const ros::WallTime now = ros::WallTime::now();
    std::lock_guard<std::mutex> lock(mutex_);
    auto found = last_.find(message);
    if (found != last_.end() && now - found->second < period_) return false;
    if (found == last_.end() && last_.size() >= kMaxMessages) forgetOldest(now);
    last_[message] = now;
    ROS_ERROR("%s", message.c_str());
    return true;
  }

  /// Messages remembered (for tests).
  size_t remembered() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_.size();
  }

 private:
  /// Forgets the messages older than the period, or else the oldest one.
  void forgetOldest(const ros::WallTime& now) {
    for (auto it = last_.begin(); it != last_.end();) {
      it = now - it->second >= period_ ? last_.erase(it) : std::next(it);
    }
    if (last_.size() < kMaxMessages) return;
    last_.erase(std::min_element(last_.begin(), last_.end(),
                                 [](const auto& a, const auto& b) { return a.second < b.second; }));
  }

  ros::WallDuration period_;
  mutable std::mutex mutex_;
  std::map<std::string, ros::WallTime> last_;
};

}  // namespace sift_hull
