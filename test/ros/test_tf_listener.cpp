// TfListener's refusals: which stamps never reach tf's buffer.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "lib/tf_listener.h"

namespace sift_hull {
namespace {

TEST(TfListener, RefusesAStampNearTheEndOfRosTime) {
  const ros::Time now(1000.0);
  const ros::Time end(std::numeric_limits<uint32_t>::max() - 5, 0);
  EXPECT_NE(TfListener::refusal(end, now, false), "");
  EXPECT_NE(TfListener::refusal(end, now, true), "");           // static ones too
  EXPECT_NE(TfListener::refusal(end, ros::Time(), false), "");  // before the clock starts too
}

TEST(TfListener, RefusesATransformAheadOfTheClockUnlessStaticOrTheClockIsZero) {
  const ros::Time now(1000.0);
  EXPECT_EQ(TfListener::refusal(now, now, false), "");
  EXPECT_EQ(TfListener::refusal(now - ros::Duration(500.0), now, false), "");  // the past
  EXPECT_EQ(TfListener::refusal(ros::Time(), now, false), "");
  const ros::Duration ahead(TfListener::kMaxAhead_s);
  EXPECT_EQ(TfListener::refusal(now + ahead, now, false), "");
  EXPECT_NE(TfListener::refusal(now + ahead + ros::Duration(0.01), now, false), "");
  EXPECT_EQ(TfListener::refusal(now + ros::Duration(100.0), now, true), "");
  EXPECT_EQ(TfListener::refusal(ros::Time(5000.0), ros::Time(), false), "");
}

}  // namespace
}  // namespace sift_hull
