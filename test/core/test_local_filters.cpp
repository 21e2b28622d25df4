// The filters that use SIFT's scale and orientation locally (lsc, local_gsc) and the guided filter,
// each against a plain slow reference written from its definition, on synthetic putatives with
// known inliers: 30 % and 60 % outliers, rotation and zoom invariance, two motions, tiny inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/spatial_neighbours.h"
#include "sift_hull/synthetic/synthetic_matches.h"
#include "synthetic_putatives.h"

namespace sift_hull {
namespace {

// ---- plain references --------------------------------------------------------------------------

/// Brute-force k nearest others, by (squared distance, index).
std::vector<std::vector<int>> referenceNeighbours(const std::vector<cv::Point2f>& points,
                                                  size_t k) {
  std::vector<std::vector<int>> result(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y)) continue;
    std::vector<std::pair<float, int>> all;
    for (size_t j = 0; j < points.size(); ++j) {
      if (j == i || !std::isfinite(points[j].x) || !std::isfinite(points[j].y)) continue;
      const float dx = points[j].x - points[i].x, dy = points[j].y - points[i].y;
      all.emplace_back(dx * dx + dy * dy, static_cast<int>(j));
    }
    std::sort(all.begin(), all.end());
    for (size_t n = 0; n < std::min(k, all.size()); ++n) result[i].push_back(all[n].second);
  }
  return result;
}

/// lsc from its definition: the similarity of match m predicts each neighbour, both ways.
std::vector<double> referenceLsc(const PutativeMatches& input, const LscConfig& config) {
  std::vector<cv::Point2f> left, right;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    left.push_back(input.left(m).pt), right.push_back(input.right(m).pt);
  }
  const size_t k = config.neighbours;
  const auto near_left = referenceNeighbours(left, k), near_right = referenceNeighbours(right, k);
  std::vector<double> support(input.matches.size());
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const double s = input.right(m).size / input.left(m).size;
    const double a = (input.right(m).angle - input.left(m).angle) * CV_PI / 180.0;
    const auto predicts = [&](cv::Point2f from, cv::Point2f offset, double scale, double angle,
                              cv::Point2f to) {
      const double px = from.x + scale * (std::cos(angle) * offset.x - std::sin(angle) * offset.y);
      const double py = from.y + scale * (std::sin(angle) * offset.x + std::cos(angle) * offset.y);
      const double tolerance =
          config.max_relative_error * scale * std::hypot(offset.x, offset.y) +
          config.min_tolerance_px;
      return std::hypot(to.x - px, to.y - py) <= tolerance;
    };
    size_t agree = 0;
    for (int n : near_left[m]) agree += predicts(right[m], left[n] - left[m], s, a, right[n]);
    for (int n : near_right[m]) agree += predicts(left[m], right[n] - right[m], 1 / s, -a, left[n]);
    support[m] = double(agree) / (near_left[m].size() + near_right[m].size());
  }
  return support;
}

using test::differing;
using test::synthetic;
using test::transformRight;
using test::twoMotions;

// ---- SpatialNeighbours -------------------------------------------------------------------------

TEST(SpatialNeighbours, EqualsBruteForceWithClustersDuplicatesAndNan) {
  std::mt19937 random(3);
  std::uniform_real_distribution<float> x(0.f, 640.f), y(0.f, 480.f), jitter(-2.f, 2.f);
  std::vector<cv::Point2f> points;
  for (int i = 0; i < 1500; ++i) points.emplace_back(x(random), y(random));
  for (int i = 0; i < 300; ++i) points.emplace_back(100.f + jitter(random), 50.f + jitter(random));
  for (int i = 0; i < 20; ++i) points.emplace_back(300.f, 200.f);  // coincident
  points.emplace_back(NAN, 4.f);
  for (size_t k : {1u, 4u, 16u, 40u}) {
    const SpatialNeighbours fast(points, k);
    const auto slow = referenceNeighbours(points, k);
    for (size_t i = 0; i < points.size(); ++i) {
      for (size_t n = 0; n < k; ++n) {
        const int expected = n < slow[i].size() ? slow[i][n] : -1;
        ASSERT_EQ(fast.of(i)[n], expected) << "point " << i << ", neighbour " << n << ", k " << k;
      }
    }
  }
}

TEST(SpatialNeighbours, TinySetsArePaddedWithMinusOne) {
  EXPECT_EQ(SpatialNeighbours({}, 4).k(), 4u);
  const SpatialNeighbours one({{1.f, 2.f}}, 3);
  EXPECT_EQ(one.of(0)[0], -1);
  const SpatialNeighbours two({{1.f, 2.f}, {1.f, 2.f}}, 3);
  EXPECT_EQ(two.of(0)[0], 1);
  EXPECT_EQ(two.of(0)[1], -1);
  EXPECT_EQ(two.of(1)[0], 0);
}

// ---- lsc ---------------------------------------------------------------------------------------

TEST(Lsc, EqualsThePlainReference) {
  for (double outliers : {0.3, 0.6}) {
    const LabelledMatches input = synthetic(outliers, 5);
    const LscConfig config;
    const FilterResult fast = filterLsc(input.putative, config);
    const std::vector<double> slow = referenceLsc(input.putative, config);
    size_t differ = 0;
    for (size_t m = 0; m < slow.size(); ++m)
      differ += fast.keep[m] != (slow[m] >= config.min_support);
    EXPECT_LE(differ, slow.size() / 500) << "float rounding only, outliers " << outliers;
  }
}

TEST(Lsc, SeparatesInliersAtThirtyAndSixtyPercentOutliers) {
  for (double outliers : {0.3, 0.6}) {
    const LabelledMatches input = synthetic(outliers, 7);
    const FilterScores scores = scoreFilter(input.truth, filterLsc(input.putative, LscConfig()));
    std::cout << "lsc at " << outliers << " outliers: P " << scores.precision() << " R "
              << scores.recall() << "\n";
    EXPECT_GE(scores.recall(), 0.95);
    EXPECT_GE(scores.precision(), outliers < 0.5 ? 0.97 : 0.93);
  }
}

TEST(LocalFilters, SameDecisionsAfterRotatingAndZoomingTheRightImage) {
  const LabelledMatches input = synthetic(0.3, 9);
  for (const std::string name : {"lsc", "local_gsc"}) {
    const auto filter = makeFilter(name, FilterConfigs());
    const FilterResult before = filter->apply(input.putative);
    for (const auto& [deg, scale] : {std::pair{90.0, 1.0}, {37.0, 2.5}, {-120.0, 0.4}}) {
      const FilterResult after = filter->apply(transformRight(input.putative, deg, scale));
      // lsc's tolerance floor is in pixels, so a zoom changes a few borderline decisions.
      EXPECT_LE(differing(before, after), input.truth.size() / 50)
          << name << " rotated " << deg << " zoomed " << scale;
    }
  }
}

TEST(Guided, SameDecisionsAfterRotatingTheRightImage) {
  // Its thresholds are in pixels (transfer error, epipolar distance), so only rotations, which
  // keep distances, must leave its decisions alone; rounding moves a few borderline ones.
  const LabelledMatches input = synthetic(0.3, 9);
  const auto filter = makeFilter("guided", FilterConfigs());
  const FilterResult before = filter->apply(input.putative);
  for (double deg : {90.0, 37.0, -120.0}) {
    const FilterResult after = filter->apply(transformRight(input.putative, deg, 1.0));
    std::cout << "guided rotated " << deg << ": " << differing(before, after) << " of "
              << input.truth.size() << " decisions differ\n";
    EXPECT_LE(differing(before, after), input.truth.size() / 100) << "rotated " << deg;  // 0
  }
}

// ---- local_gsc ---------------------------------------------------------------------------------

TEST(LocalGsc, SeparatesInliersAtThirtyPercentOutliers) {
  const LabelledMatches input = synthetic(0.3, 11);
  const FilterScores scores =
      scoreFilter(input.truth, filterLocalGsc(input.putative, LocalGscConfig()));
  EXPECT_GE(scores.recall(), 0.9);
  EXPECT_GE(scores.precision(), 0.9);
}

TEST(LocalGsc, HistogramOverTheNeighbourUnionMatchesItsDefinition) {
  // Four matches, a pure shift: every histogram equal left and right, distance 0.
  PutativeMatches input;
  const std::vector<cv::Point2f> points = {{0, 0}, {10, 0}, {0, 10}, {10, 10}};
  for (size_t i = 0; i < points.size(); ++i) {
    input.left_keypoints.emplace_back(points[i], 4.f, 30.f);
    input.right_keypoints.emplace_back(points[i] + cv::Point2f(5, 7), 4.f, 30.f);
    input.matches.emplace_back(int(i), int(i), 0.f);
  }
  LocalGscConfig config;
  config.neighbours = 2;
  const FilterResult shifted = filterLocalGsc(input, config);
  for (double score : shifted.score) EXPECT_EQ(score, 0.0);
  // Swapping two right points breaks the layout around them.
  std::swap(input.right_keypoints[1].pt, input.right_keypoints[2].pt);
  const FilterResult swapped = filterLocalGsc(input, config);
  EXPECT_GT(swapped.score[1], 0.5);
}

// ---- guided ---------------------------------------------------------------------------

TEST(Guided, FindsBothMotionsWhereOneModelFails) {
  const LabelledMatches input = twoMotions();
  const FilterScores guided =
      scoreFilter(input.truth, makeFilter("guided", FilterConfigs())->apply(input.putative));
  const FilterScores magsac =
      scoreFilter(input.truth, makeFilter("magsac", FilterConfigs())->apply(input.putative));
  std::cout << "two motions: guided R " << guided.recall() << " P " << guided.precision()
            << ", magsac R " << magsac.recall() << "\n";
  EXPECT_GE(guided.recall(), 0.9);
  EXPECT_GE(guided.precision(), 0.95);
  EXPECT_LT(magsac.recall(), 0.7);  // one model explains one object
}

TEST(Guided, ASimilarityPairIsFittedByTheHomography) {
  for (double outliers : {0.3, 0.6}) {
    const LabelledMatches input = synthetic(outliers, 23);
    const FilterScores scores =
        scoreFilter(input.truth, makeFilter("guided", FilterConfigs())->apply(input.putative));
    EXPECT_GE(scores.recall(), 0.95) << outliers;
    EXPECT_GE(scores.precision(), 0.97) << outliers;
  }
}

TEST(Guided, RejudgesEveryPutativeNotOnlyTheSurvivors) {
  const LabelledMatches input = synthetic(0.6, 29);
  FilterConfigs strict;
  strict.lsc.min_support = 0.3;  // lsc alone then drops many inliers among 60 % mismatches
  const FilterResult lsc = makeFilter("lsc", strict)->apply(input.putative);
  const FilterResult guided = makeFilter("guided", strict)->apply(input.putative);
  EXPECT_GT(scoreFilter(input.truth, guided).correct_kept,
            scoreFilter(input.truth, lsc).correct_kept + 20);
}

TEST(Guided, SeedsRepeat) {
  const LabelledMatches input = synthetic(0.3, 31);
  FilterConfigs configs;
  configs.magsac.seed = 4;
  const FilterResult a = makeFilter("guided", configs)->apply(input.putative);
  EXPECT_EQ(makeFilter("guided", configs)->apply(input.putative).keep, a.keep);
}

TEST(Guided, TinyAndDegenerateInputsKeepNothingWithoutThrowing) {
  for (size_t n : {0u, 1u, 7u, 19u}) {
    LabelledMatches input = synthetic(0.0, 37);
    input.putative.matches.resize(std::min(n, input.putative.matches.size()));
    const FilterResult result = makeFilter("guided", FilterConfigs())->apply(input.putative);
    EXPECT_EQ(result.keptCount(), 0u) << n << " matches: fewer than a motion needs";
  }
  PutativeMatches same;  // every match at one point: no motion can be fitted
  for (int i = 0; i < 50; ++i) {
    same.left_keypoints.emplace_back(cv::Point2f(5, 5), 4.f, 0.f);
    same.right_keypoints.emplace_back(cv::Point2f(9, 9), 4.f, 0.f);
    same.matches.emplace_back(i, i, 0.f);
  }
  EXPECT_NO_THROW(makeFilter("guided", FilterConfigs())->apply(same));
}

TEST(LocalFilters, RejectInvalidConfigs) {
  std::vector<FilterConfigs> bad(6);
  bad[0].lsc.neighbours = 0;
  bad[1].lsc.min_support = 1.5;
  bad[2].lsc.max_relative_error = NAN;
  bad[3].local_gsc.neighbours = 5000;
  bad[4].guided.min_model_inliers = 3;
  bad[5].guided.max_transfer_px = 0.0;
  for (const FilterConfigs& configs : bad) EXPECT_THROW(validate(configs), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
