// The vote's densest window (src/core/filters/densest_window.h) against a plain quadratic search:
// on a line and on a circle, with ties, repeated values and too few candidates.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "filters/densest_window.h"

namespace sift_hull {
namespace {

double separationOf(double a, double b, double period) {
  const double d = std::abs(a - b);
  return period > 0.0 ? std::min(d, period - d) : d;
}

/// The definition, in O(n^2): the candidate with the most candidates within `half` (ties: the
/// lowest index), and those candidates in order.
std::vector<int> plainWindow(const std::vector<float>& values, const std::vector<int>& candidates,
                             double half, double period, size_t* count) {
  int centre = -1;
  size_t best = 0;
  for (int c : candidates) {
    size_t within = 0;
    for (int o : candidates) within += separationOf(values[o], values[c], period) <= half;
    if (within > best || (within == best && c < centre)) best = within, centre = c;
  }
  *count = best;
  std::vector<int> members;
  for (int o : candidates) {
    if (centre >= 0 && separationOf(values[o], values[centre], period) <= half) {
      members.push_back(o);
    }
  }
  return members;
}

TEST(DensestWindow, MatchesThePlainSearchOnALineAndOnACircle) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    const bool circle = trial % 2 == 0;
    const double period = circle ? 360.0 : 0.0, half = circle ? 15.0 : 0.25;
    const size_t n = 1 + size_t(trial) * 3;
    std::uniform_real_distribution<float> spread(circle ? 0.f : -3.f, circle ? 359.99f : 3.f);
    std::normal_distribution<float> cluster(circle ? 355.f : 0.5f, circle ? 8.f : 0.1f);
    std::vector<float> values(n);
    for (size_t i = 0; i < n; ++i) {
      float v = i % 3 == 0 ? spread(random) : cluster(random);
      if (circle) v = std::fmod(std::fmod(v, 360.f) + 360.f, 360.f);
      if (i % 17 == 5) v = values[i / 2];  // repeated values: ties between centres
      values[i] = v;
    }
    std::vector<int> candidates;  // every index but a few, in order
    for (size_t i = 0; i < n; ++i) {
      if (i % 11 != 3) candidates.push_back(int(i));
    }
    size_t count = 0, expected_count = 0;
    const std::vector<int> found = detail::densestWindow(values, candidates, half, period, &count);
    const std::vector<int> expected =
        plainWindow(values, candidates, half, period, &expected_count);
    ASSERT_EQ(count, expected_count) << "trial " << trial;
    EXPECT_EQ(found, expected) << "trial " << trial;
  }
}

TEST(DensestWindow, AWindowAcrossZeroDegreesCountsBothSides) {
  // Centred on 1 deg: 358.5 is 2.5 deg away across zero, 359 two, 2 one.
  const std::vector<float> values{359.f, 1.f, 2.f, 180.f, 358.5f};
  size_t count = 0;
  const std::vector<int> found = detail::densestWindow(values, {0, 1, 2, 3, 4}, 2.5, 360.0, &count);
  EXPECT_EQ(count, 4u);
  EXPECT_EQ(found, (std::vector<int>{0, 1, 2, 4}));
}

TEST(DensestWindow, TiesGoToTheLowestIndexAndNoCandidatesGiveNone) {
  // Index 0 (50) and index 1 (10) each see two; the lower index wins although its value is the
  // larger and comes later in sorted order.
  const std::vector<float> values{50.f, 10.f, 50.f, 10.f};
  size_t count = 0;
  EXPECT_EQ(detail::densestWindow(values, {1, 2, 3, 0}, 1.0, 0.0, &count),
            (std::vector<int>{2, 0}));
  EXPECT_EQ(count, 2u);
  EXPECT_TRUE(detail::densestWindow(values, {}, 1.0, 0.0, &count).empty());
  EXPECT_EQ(count, 0u);
}

}  // namespace
}  // namespace sift_hull
