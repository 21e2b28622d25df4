// PairingWatch: inputs that arrive without pairing are reported after the patience, with their
// counts and newest stamps; a pair clears it. Each input's messages left out of every pair are
// counted since the start.

#include <gtest/gtest.h>

#include "lib/pairing_watch.h"

namespace sift_hull {
namespace {

using Clock = PairingWatch::Clock;
using std::chrono::milliseconds;

TEST(PairingWatch, SaysNothingWhileInputsPairOrNothingArrives) {
  PairingWatch watch({"left", "right"}, 3.0, "HINT");
  const Clock::time_point start{};
  EXPECT_EQ(watch.problem(start + milliseconds(10000)), "") << "nothing arrived";
  for (int i = 0; i < 10; ++i) {
    const Clock::time_point now = start + milliseconds(1000 * i);
    watch.arrived(0, i, now);
    watch.arrived(1, i, now);
    watch.paired();
    EXPECT_EQ(watch.problem(now + milliseconds(2999)), "");
  }
}

TEST(PairingWatch, ReportsInputsThatArriveWithoutPairingAfterThePatience) {
  PairingWatch watch({"left/image", "right/image"}, 3.0, "stamps must be equal");
  const Clock::time_point start{};
  for (int i = 0; i < 4; ++i) {
    watch.arrived(0, 10.0 + i, start + milliseconds(1000 * i));
    watch.arrived(1, 10.005 + i, start + milliseconds(1000 * i));
  }
  EXPECT_EQ(watch.problem(start + milliseconds(2999)), "") << "within the patience";
  const std::string problem = watch.problem(start + milliseconds(3000));
  EXPECT_EQ(problem,
            "inputs arrive but have not paired for 3 s, messages since the last pair: "
            "left/image (4, newest stamp 13.000 s), right/image (4, newest stamp 13.005 s): "
            "stamps must be equal");
  watch.paired();
  EXPECT_EQ(watch.problem(start + milliseconds(9000)), "");
}

TEST(PairingWatch, NamesAnInputThatNeverArrives) {
  PairingWatch watch({"silhouette", "camera_info"}, 1.0, "HINT");
  watch.arrived(0, 5.0, Clock::time_point{});
  watch.arrived(7, 5.0, Clock::time_point{});  // no such input: ignored
  EXPECT_NE(watch.problem(Clock::time_point{} + milliseconds(1500)).find("camera_info (0)"),
            std::string::npos);
}

TEST(PairingWatch, TakesAnInputThatCameBeforeButNotSinceForIdle) {
  PairingWatch watch({"silhouette", "camera_info"}, 1.0, "HINT");
  const Clock::time_point start{};
  watch.arrived(0, 1.0, start);
  watch.arrived(1, 1.0, start);
  watch.paired();
  for (int i = 1; i <= 10; ++i) watch.arrived(1, 1.0 + i, start + milliseconds(300 * i));
  EXPECT_EQ(watch.problem(start + milliseconds(3000)), "")
      << "camera_info streaming between masks that come now and then";
}

TEST(PairingWatch, CountsEachInputsMessagesLeftOutOfEveryPair) {
  PairingWatch watch({"left/image", "right/image"}, 3.0, "HINT");
  const Clock::time_point now{};
  for (int i = 0; i < 10; ++i) watch.arrived(0, i, now);  // 10 left images
  for (int i = 0; i < 7; ++i) watch.arrived(1, i, now);   // 7 right ones, 6 of them paired
  for (int i = 0; i < 6; ++i) watch.paired();
  const std::vector<PairingWatch::Total> totals = watch.totals();
  ASSERT_EQ(totals.size(), 2u);
  EXPECT_EQ(totals[0].name, "left/image");
  EXPECT_EQ(totals[0].received, 10u);
  EXPECT_EQ(totals[0].unpaired, 4u);
  EXPECT_EQ(totals[1].name, "right/image");
  EXPECT_EQ(totals[1].received, 7u);
  EXPECT_EQ(totals[1].unpaired, 1u);
}

}  // namespace
}  // namespace sift_hull
