#pragma once

#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace sift_hull {

/// Silhouettes waiting for their camera's pose in tf, by frame id and stamp: a silhouette whose
/// pose has not come within the timeout is reported once, and is not carved even if the pose
/// comes later. At most `capacity` waits are remembered (the oldest are forgotten first).
class PoseWaits {
 public:
  using Clock = std::chrono::steady_clock;

  /// timeout_s <= 0: no timeout.
  PoseWaits(double timeout_s, size_t capacity)
      : timeout_(toDuration(timeout_s)), capacity_(capacity) {}

  /// A view starts waiting. False, and nothing changes, when a view of the same frame id and
  /// stamp is known already (waiting, or expired and not yet forgotten): two such views would be
  /// one wait, and the second would be carved or lost uncounted.
  bool arrived(const std::string& frame, double stamp_s, Clock::time_point now) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!waits_.emplace(Key{frame, stamp_s}, Wait{now, false}).second) return false;
    while (waits_.size() > capacity_) waits_.erase(oldest());
    return true;
  }

  /// The pose came: forgets the wait; false when it had timed out (the view must not be carved).
  bool posed(const std::string& frame, double stamp_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = waits_.find({frame, stamp_s});
    if (found == waits_.end()) return true;
    const bool in_time = !found->second.expired;
    waits_.erase(found);
    return in_time;
  }

  /// tf gave up on it (dropped from its queue): forgets the wait. True when this is the first
  /// word of its loss: false when expire() has reported it already or the wait is unknown, so
  /// that a dropped view is counted once. (The wait is always known in the node: its capacity
  /// is four times tf's queue, which drops a silhouette before this would.)
  bool forget(const std::string& frame, double stamp_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = waits_.find({frame, stamp_s});
    if (found == waits_.end()) return false;
    const bool unreported = !found->second.expired;
    waits_.erase(found);
    return unreported;
  }

  /// The frame ids of the waits that passed the timeout since the last call, each once.
  std::vector<std::string> expire(Clock::time_point now) {
    std::vector<std::string> frames;
    if (timeout_ <= Clock::duration::zero()) return frames;
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [key, wait] : waits_) {
      if (wait.expired || now - wait.since < timeout_) continue;
      wait.expired = true;
      frames.push_back(key.first);
    }
    return frames;
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return waits_.size();
  }

  /// Forgets every wait; returns how many had not expired.
  size_t clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t waiting = 0;
    for (const auto& entry : waits_) waiting += entry.second.expired ? 0 : 1;
    waits_.clear();
    return waiting;
  }

 private:
  struct Wait {
    Clock::time_point since;
    bool expired = false;
  };
  using Key = std::pair<std::string, double>;

  static Clock::duration toDuration(double seconds) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  }

  std::map<Key, Wait>::iterator oldest() {
    auto oldest = waits_.begin();
    for (auto it = waits_.begin(); it != waits_.end(); ++it) {
      if (it->second.since < oldest->second.since) oldest = it;
    }
    return oldest;
  }

  const Clock::duration timeout_;
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::map<Key, Wait> waits_;
};

}  // namespace sift_hull
