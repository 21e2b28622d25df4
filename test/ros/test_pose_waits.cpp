// The hull node's record of silhouettes waiting for their pose: reported once after the timeout,
// refused when the pose comes too late, forgotten when tf gives up (a dropped view counted once),
// bounded in size.

#include <gtest/gtest.h>

#include "lib/pose_waits.h"

namespace sift_hull {
namespace {

using std::chrono::milliseconds;

TEST(PoseWaits, ReportsAWaitOnceAfterTheTimeoutAndRefusesItsLatePose) {
  PoseWaits waits(1.0, 10);
  const auto t0 = PoseWaits::Clock::now();
  waits.arrived("camera_a", 1.0, t0);
  waits.arrived("camera_b", 1.0, t0 + milliseconds(600));
  EXPECT_TRUE(waits.expire(t0 + milliseconds(900)).empty());
  EXPECT_EQ(waits.expire(t0 + milliseconds(1100)), std::vector<std::string>{"camera_a"});
  EXPECT_TRUE(waits.expire(t0 + milliseconds(1200)).empty());  // once
  EXPECT_FALSE(waits.posed("camera_a", 1.0));                  // too late: not carved
  EXPECT_TRUE(waits.posed("camera_b", 1.0));                   // in time
  EXPECT_EQ(waits.size(), 0u);
  EXPECT_TRUE(waits.posed("camera_unknown", 2.0));
}

TEST(PoseWaits, ForgetsWhatTfGaveUpOnAndStaysBounded) {
  PoseWaits waits(1.0, 3);
  const auto t0 = PoseWaits::Clock::now();
  for (int i = 0; i < 5; ++i) waits.arrived("camera", i, t0 + milliseconds(i));
  EXPECT_EQ(waits.size(), 3u);
  EXPECT_TRUE(waits.posed("camera", 0.0));   // forgotten as the oldest: unknown
  EXPECT_TRUE(waits.forget("camera", 4.0));  // not reported yet: the caller counts it
  EXPECT_EQ(waits.size(), 2u);
  // Reported by expire() already: forgetting it must not count the same view twice.
  EXPECT_EQ(waits.expire(t0 + milliseconds(1100)).size(), 2u);
  EXPECT_FALSE(waits.forget("camera", 3.0));
  EXPECT_FALSE(waits.forget("camera", 9.0));  // never seen
  EXPECT_FALSE(waits.forget("camera", 4.0));  // forgotten already
  EXPECT_EQ(waits.size(), 1u);
}

TEST(PoseWaits, ASecondViewOfOneFrameAndStampIsRefusedWhileTheFirstWaits) {
  PoseWaits waits(1.0, 8);
  const auto t0 = PoseWaits::Clock::now();
  EXPECT_TRUE(waits.arrived("camera", 1.0, t0));
  EXPECT_FALSE(waits.arrived("camera", 1.0, t0 + std::chrono::milliseconds(10)));
  EXPECT_TRUE(waits.arrived("camera", 2.0, t0));        // another stamp
  EXPECT_TRUE(waits.arrived("other_camera", 1.0, t0));  // another frame
  EXPECT_EQ(waits.size(), 3u);
  // The first wait kept its own start: it expires at t0 + 1 s, not 10 ms later.
  EXPECT_EQ(waits.expire(t0 + std::chrono::milliseconds(1005)).size(), 3u);
  EXPECT_TRUE(waits.posed("camera", 3.0));  // unknown: carved
  EXPECT_FALSE(waits.posed("camera", 1.0));
  EXPECT_TRUE(waits.arrived("camera", 1.0, t0));  // the first is gone: a new view of it waits
}

TEST(PoseWaits, NoTimeoutWhenNotPositive) {
  PoseWaits waits(0.0, 3);
  const auto t0 = PoseWaits::Clock::now();
  waits.arrived("camera", 1.0, t0);
  EXPECT_TRUE(waits.expire(t0 + std::chrono::hours(1)).empty());
  EXPECT_TRUE(waits.posed("camera", 1.0));
}

}  // namespace
}  // namespace sift_hull
