#pragma once

#include <ros/ros.h>

#include <functional>

namespace sift_hull {
namespace test {

/// The deadline of every wait in the rostests.
constexpr double kDeadline_s = 30.0;

/// Spins until `done` holds or the deadline passes; returns `done()`.
inline bool waitFor(const std::function<bool()>& done, double seconds = kDeadline_s) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return done();
}

}  // namespace test
}  // namespace sift_hull
