#pragma once

#include <ros/ros.h>

#include <functional>

#include "lib/wall_wait.h"

namespace sift_hull {
namespace test {

/// The deadline of every wait in the rostests.
constexpr double kDeadline_s = 30.0;

/// Spins until `done` holds or the deadline passes; returns `done()`.
inline bool waitFor(const std::function<bool()>& done, double seconds = kDeadline_s) {
  return waitOnWallClock(done, seconds, 0.01, [] { ros::spinOnce(); });
}

}  // namespace test
}  // namespace sift_hull
