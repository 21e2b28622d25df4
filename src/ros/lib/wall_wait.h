#pragma once

#include <ros/init.h>
#include <ros/time.h>

#include <functional>

namespace sift_hull {

/// Checks `done` every `poll_s` seconds of wall time (ROS time stands still with a stopped bag
/// clock) until it holds or `seconds` have passed; `before_each_check` runs first each time
/// (ros::spinOnce, say). Stops early when ROS shuts down. Returns done().
inline bool waitOnWallClock(const std::function<bool()>& done, double seconds, double poll_s,
                            const std::function<void()>& before_each_check = {}) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (before_each_check) before_each_check();
    if (done()) return true;
    ros::WallDuration(poll_s).sleep();
  }
  return done();
}

/// Sleeps until `due` on the wall clock; returns at once when it has passed. (A negative
/// ros::WallDuration must never be slept: roscpp takes its seconds as unsigned and sleeps for
/// decades.)
inline void sleepUntilWall(const ros::WallTime& due) {
  const ros::WallDuration left = due - ros::WallTime::now();
  if (left > ros::WallDuration(0.0)) left.sleep();
}

}  // namespace sift_hull
