// The nodes' error log: throttled per message, so a different problem is reported at once, and
// bounded, so messages carrying changing values cannot grow it.

#include <gtest/gtest.h>

#include <string>

#include "lib/throttled_log.h"

namespace sift_hull {
namespace {

TEST(ThrottledLog, ADifferentMessageIsLoggedAtOnceTheSameOneIsThrottled) {
  ros::Time::init();
  ThrottledLog log(60.0);
  EXPECT_TRUE(log.error("hull: view 'a' ignored: ", "camera_info K is all zero"));
  EXPECT_TRUE(
      log.error("hull: view 'a' ignored: ", "camera_info K holds a value that is not finite"));
  EXPECT_FALSE(log.error("hull: view 'a' ignored: ", "camera_info K is all zero"));
  EXPECT_TRUE(log.error("hull: view 'b' ignored: ", "camera_info K is all zero"));
}

TEST(ThrottledLog, RemembersABoundedNumberOfMessages) {
  ros::Time::init();
  ThrottledLog log(60.0);
  for (int i = 0; i < 10000; ++i) {
    EXPECT_TRUE(log.error("matcher: pair ignored: ", "image " + std::to_string(i)));
    ASSERT_LE(log.remembered(), ThrottledLog::kMaxMessages);
  }
  // The newest messages are still throttled, the oldest forgotten.
  EXPECT_FALSE(log.error("matcher: pair ignored: ", "image 9999"));
  EXPECT_TRUE(log.error("matcher: pair ignored: ", "image 0"));
}

TEST(ThrottledLog, LogsAgainAfterThePeriod) {
  ros::Time::init();
  ThrottledLog log(0.05);
  EXPECT_TRUE(log.error("x: ", "y"));
  ros::WallDuration(0.1).sleep();
  EXPECT_TRUE(log.error("x: ", "y"));
}

}  // namespace
}  // namespace sift_hull
