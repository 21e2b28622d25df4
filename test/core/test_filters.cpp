#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <iostream>
#include <random>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/epipolar.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/gsc.h"
#include "sift_hull/filters/robust_fit.h"
#include "sift_hull/synthetic/synthetic_matches.h"

namespace sift_hull {
namespace {

// ---- a plain reference of the GSC, written from its definition ---------------------------------

/// cos and sin of a keypoint angle as the filter rounds them: float, exact at multiples of 90.
void referenceDirection(float angle_deg, float* c, float* s) {
  const double reduced = std::fmod(static_cast<double>(angle_deg), 360.0);
  if (std::fmod(reduced, 90.0) == 0.0) {
    const int quarter = static_cast<int>(std::lround(reduced / 90.0) + 4) % 4;
    *c = quarter == 0 ? 1.f : quarter == 2 ? -1.f : 0.f;
    *s = quarter == 1 ? 1.f : quarter == 3 ? -1.f : 0.f;
    return;
  }
  *c = static_cast<float>(std::cos(reduced * M_PI / 180.0));
  *s = static_cast<float>(std::sin(reduced * M_PI / 180.0));
}

/// Sector of the polar angle of (a, b): [45k, 45k + 45) degrees, a point on the polar axis line
/// counting above it, a point on another border in the sector farther from the axis direction.
int referenceSector(float a, float b) {
  if (b == 0.f) return a > 0.f ? 0 : 3;
  if (a == 0.f) return b > 0.f ? 2 : 5;
  if (a == b) return a > 0.f ? 1 : 4;
  if (a == -b) return b > 0.f ? 3 : 6;
  double degrees = std::atan2(static_cast<double>(b), static_cast<double>(a)) * 180.0 / M_PI;
  if (degrees < 0.0) degrees += 360.0;
  return std::min(7, static_cast<int>(std::floor(degrees / 45.0)));
}

GscHistogram referenceHistogram(const std::vector<cv::KeyPoint>& points, size_t i) {
  float c, s;
  referenceDirection(points[i].angle, &c, &s);
  const float xi = points[i].pt.x, yi = points[i].pt.y;
  // The filter's rounding: coordinates along and across the orientation, with fused
  // multiply-adds, relative to the rounded offsets of the keypoint itself.
  const float offset_a = std::fma(xi, c, yi * s), offset_b = std::fma(yi, c, -(xi * s));
  GscHistogram histogram{};
  int counted = 0;
  for (const cv::KeyPoint& other : points) {
    if (other.pt.x == xi && other.pt.y == yi) continue;  // coincident: no polar angle
    const float a = std::fma(other.pt.x, c, std::fma(other.pt.y, s, -offset_a));
    const float b = std::fma(other.pt.y, c, std::fma(other.pt.x, -s, -offset_b));
    histogram[referenceSector(a, b)] += 1.0;
    ++counted;
  }
  for (double& bin : histogram) bin = counted > 0 ? bin / counted : 0.0;
  return histogram;
}

std::vector<cv::KeyPoint> leftPoints(const PutativeMatches& input) {
  std::vector<cv::KeyPoint> points;
  for (size_t m = 0; m < input.matches.size(); ++m) points.push_back(input.left(m));
  return points;
}

std::vector<cv::KeyPoint> rightPoints(const PutativeMatches& input) {
  std::vector<cv::KeyPoint> points;
  for (size_t m = 0; m < input.matches.size(); ++m) points.push_back(input.right(m));
  return points;
}

/// Matches on a small integer grid with keypoint angles at multiples of 45 degrees: many points
/// lie exactly on sector borders, and some coincide.
PutativeMatches borderHeavyMatches(size_t count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> cell(0, 12), quarter(0, 7);
  PutativeMatches input;
  input.left_image_size = input.right_image_size = cv::Size(200, 200);
  for (size_t m = 0; m < count; ++m) {
    input.left_keypoints.emplace_back(8.f * cell(random), 8.f * cell(random), 4.f,
                                      45.f * quarter(random));
    input.right_keypoints.emplace_back(8.f * cell(random), 8.f * cell(random), 4.f,
                                       45.f * quarter(random));
    input.matches.emplace_back(static_cast<int>(m), static_cast<int>(m), 0.f);
  }
  return input;
}

void expectHistogramsEqual(const GscHistogram& expected, const GscHistogram& actual,
                           const std::string& what) {
  for (int k = 0; k < kGscSectors; ++k) {
    EXPECT_DOUBLE_EQ(expected[k], actual[k]) << what << ", sector " << k;
  }
}

void expectAgreesWithReference(const PutativeMatches& input, const std::string& what) {
  const std::vector<cv::KeyPoint> left = leftPoints(input), right = rightPoints(input);
  GscConfig config;
  const FilterResult result = filterGsc(input, config);
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const GscHistograms expected{referenceHistogram(left, m), referenceHistogram(right, m)};
    const GscHistograms actual = gscHistograms(input, m);
    expectHistogramsEqual(expected.left, actual.left, what + " left, match " + std::to_string(m));
    expectHistogramsEqual(expected.right, actual.right,
                          what + " right, match " + std::to_string(m));
    EXPECT_NEAR(expected.distance(), result.score[m], 1e-12) << what << ", match " << m;
    EXPECT_EQ(expected.distance() <= config.max_histogram_distance, result.keep[m] != 0);
  }
}

TEST(GscReference, AgreesOnSectorBordersAndCoincidentPoints) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    expectAgreesWithReference(borderHeavyMatches(150, seed), "seed " + std::to_string(seed));
  }
}

TEST(GscReference, AgreesOnRandomMatchesAcrossBlocksAndThreads) {
  // 1300 matches: several counter blocks of 240 points, padding, and more than one thread.
  SyntheticMatchConfig config;
  config.inliers = 910;
  const LabelledMatches synthetic = syntheticMatches(config);
  ASSERT_EQ(synthetic.putative.matches.size(), 1300u);
  const std::vector<cv::KeyPoint> left = leftPoints(synthetic.putative);
  const FilterResult threaded = filterGsc(synthetic.putative, GscConfig{0.2, 2});
  const FilterResult single = filterGsc(synthetic.putative, GscConfig{0.2, 1});
  for (size_t m = 0; m < synthetic.putative.matches.size(); m += 7) {
    expectHistogramsEqual(referenceHistogram(left, m), gscHistograms(synthetic.putative, m).left,
                          "match " + std::to_string(m));
  }
  EXPECT_EQ(threaded.score, single.score);
}

/// The sampled gsc from its definition: the histograms over the sample the filter draws (the
/// valid matches shuffled by mt19937(1), the first M), coincident sample points left out.
double referenceSampledDistance(const PutativeMatches& input, size_t m, size_t support) {
  std::vector<size_t> chosen(input.matches.size());
  for (size_t i = 0; i < chosen.size(); ++i) chosen[i] = i;
  std::shuffle(chosen.begin(), chosen.end(), std::mt19937(1));
  chosen.resize(support);
  std::vector<cv::KeyPoint> left, right;
  for (size_t c : chosen) left.push_back(input.left(c)), right.push_back(input.right(c));
  left.push_back(input.left(m)), right.push_back(input.right(m));
  return GscHistograms{referenceHistogram(left, left.size() - 1),
                       referenceHistogram(right, right.size() - 1)}
      .distance();
}

TEST(GscSampled, EqualsItsReferenceAndKeepsNearlyEveryExactDecision) {
  SyntheticMatchConfig config;
  config.inliers = 1400;  // 2000 matches with 30 % outliers
  const LabelledMatches synthetic = syntheticMatches(config);
  GscConfig sampled;
  sampled.max_support = 256;
  const FilterResult fast = filterGsc(synthetic.putative, sampled);
  for (size_t m = 0; m < synthetic.truth.size(); m += 13) {
    EXPECT_NEAR(fast.score[m], referenceSampledDistance(synthetic.putative, m, 256), 1e-12) << m;
  }
  const FilterResult exact = filterGsc(synthetic.putative, GscConfig());
  size_t same = 0;
  for (size_t m = 0; m < exact.keep.size(); ++m) same += exact.keep[m] == fast.keep[m];
  std::cout << same << " of " << exact.keep.size() << " decisions as the exact gsc (M = 256)\n";
  EXPECT_GE(same, 0.97 * exact.keep.size());
  EXPECT_EQ(filterGsc(synthetic.putative, sampled).score, fast.score) << "a fixed sample";
  sampled.max_support = 5000;  // more than the matches: the exact filter
  EXPECT_EQ(filterGsc(synthetic.putative, sampled).score, exact.score);
}

TEST(GscReference, SectorOfEachBorderDirection) {
  // One keypoint at the origin with orientation 0, one other point on each border ray.
  const std::vector<std::pair<cv::Point2f, int>> border_points = {
      {{5, 0}, 0},  {{5, 5}, 1},   {{0, 5}, 2},  {{-5, 5}, 3},
      {{-5, 0}, 3}, {{-5, -5}, 4}, {{0, -5}, 5}, {{5, -5}, 6}};
  for (const auto& [point, sector] : border_points) {
    PutativeMatches input;
    input.left_keypoints = {cv::KeyPoint(100, 100, 4, 0),
                            cv::KeyPoint(cv::Point2f(100, 100) + point, 4, 0)};
    input.right_keypoints = input.left_keypoints;
    input.matches = {cv::DMatch(0, 0, 0.f), cv::DMatch(1, 1, 0.f)};
    const GscHistograms histograms = gscHistograms(input, 0);
    EXPECT_EQ(histograms.left[sector], 1.0) << "point (" << point.x << ", " << point.y << ")";
    EXPECT_EQ(referenceSector(point.x, point.y), sector);
  }
}

// ---- quality on synthetic ground truth
// -----------------------------------------------------------

struct Outcome {
  double inliers_kept, outliers_removed;
};

Outcome outcome(const LabelledMatches& matches, const FilterResult& result) {
  size_t inliers = 0, kept = 0, outliers = 0, removed = 0;
  for (size_t m = 0; m < matches.truth.size(); ++m) {
    if (matches.truth[m] == MatchTruth::kCorrect) {
      ++inliers;
      kept += result.keep[m];
    } else {
      ++outliers;
      removed += !result.keep[m];
    }
  }
  return {static_cast<double>(kept) / inliers, static_cast<double>(removed) / outliers};
}

class GscSyntheticTest : public ::testing::TestWithParam<unsigned> {};

TEST_P(GscSyntheticTest, RemovesOutliersKeepsInliersAtThirtyPercent) {
  SyntheticMatchConfig config;
  config.seed = GetParam();
  config.inliers = 700;
  config.outlier_fraction = 0.3;
  const LabelledMatches matches = syntheticMatches(config);
  const Outcome result = outcome(matches, filterGsc(matches.putative, GscConfig()));
  // Measured with seeds 1..4: inliers kept 1.000 each, outliers removed 0.927 to 0.947.
  EXPECT_GE(result.inliers_kept, 0.95) << "seed " << config.seed;
  EXPECT_GE(result.outliers_removed, 0.90) << "seed " << config.seed;
}

INSTANTIATE_TEST_SUITE_P(Seeds, GscSyntheticTest, ::testing::Values(1u, 2u, 3u, 4u));

/// A rectified pair: the right points are the left ones shifted by a disparity, on the same rows.
LabelledMatches rectifiedPair(size_t count, double disparity_px, unsigned seed) {
  SyntheticMatchConfig config;
  config.inliers = count;
  config.outlier_fraction = 0.0;
  config.rotation_deg = 0.0;
  config.scale = 1.0;
  config.shift_px = 0.0;
  config.position_noise_px = 0.0;
  config.angle_noise_deg = 0.0;
  config.seed = seed;
  LabelledMatches matches = syntheticMatches(config);
  for (cv::KeyPoint& right : matches.putative.right_keypoints) right.pt.x -= disparity_px;
  matches.putative.F_right_left = rectifiedFundamentalMatrix();
  return matches;
}

TEST(EpipolarVersusGsc, MismatchOnTheSameEpipolarLinePassesEpipolarButNotGsc) {
  LabelledMatches matches = rectifiedPair(300, 0.0, 5);
  // Repetitive structure: a left point matched to a look-alike 250 px along the same row.
  PutativeMatches& input = matches.putative;
  input.left_keypoints.emplace_back(100.f, 240.f, 4.f, 30.f);
  input.right_keypoints.emplace_back(350.f, 240.f, 4.f, 30.f);
  const int last = static_cast<int>(input.left_keypoints.size()) - 1;
  input.matches.emplace_back(last, last, 0.f);
  const size_t mismatch = input.matches.size() - 1;

  const FilterResult epipolar = filterEpipolar(input, EpipolarConfig());
  const FilterResult gsc = filterGsc(input, GscConfig());
  EXPECT_TRUE(epipolar.keep[mismatch]);
  EXPECT_NEAR(epipolar.score[mismatch], 0.0, 1e-9);
  EXPECT_FALSE(gsc.keep[mismatch]) << "histogram distance " << gsc.score[mismatch];
  EXPECT_EQ(epipolar.keptCount(), input.matches.size());
  EXPECT_GE(gsc.keptCount(), input.matches.size() - 1 - 3);  // the inliers stay
}

TEST(Epipolar, ScoreIsTheLargerPointToLineDistance) {
  LabelledMatches matches = rectifiedPair(3, 20.0, 2);
  matches.putative.right_keypoints[1].pt.y += 1.5f;
  matches.putative.right_keypoints[2].pt.y -= 3.0f;
  const FilterResult result = filterEpipolar(matches.putative, EpipolarConfig{2.0});
  EXPECT_NEAR(result.score[0], 0.0, 1e-4);
  EXPECT_NEAR(result.score[1], 1.5, 1e-4);
  EXPECT_NEAR(result.score[2], 3.0, 1e-4);
  EXPECT_EQ(result.keep, (std::vector<uint8_t>{1, 1, 0}));
}

TEST(Epipolar, WithoutCalibrationThrows) {
  LabelledMatches matches = rectifiedPair(3, 20.0, 2);
  matches.putative.F_right_left.reset();
  EXPECT_THROW(filterEpipolar(matches.putative, EpipolarConfig()), std::invalid_argument);
}

TEST(RobustFit, RansacAndMagsacSeparateARectifiedPairFromOutliers) {
  LabelledMatches matches = rectifiedPair(400, 25.0, 3);
  for (cv::KeyPoint& left : matches.putative.left_keypoints) left.pt.y += 0.0f;
  injectMismatches(&matches, 0.3, 9);
  for (const std::string name : {"ransac", "magsac"}) {
    const Outcome result =
        outcome(matches, makeFilter(name, FilterConfigs())->apply(matches.putative));
    EXPECT_GE(result.inliers_kept, 0.95) << name;
    EXPECT_GE(result.outliers_removed, 0.95) << name;
  }
}

// ---- composition and the factory --------------------------------------------------------------

TEST(Composition, KeepsWhatEveryPartKeeps) {
  LabelledMatches matches = rectifiedPair(200, 10.0, 4);
  injectMismatches(&matches, 0.3, 4);
  const FilterConfigs configs;
  const FilterResult epipolar = filterEpipolar(matches.putative, configs.epipolar);
  const FilterResult gsc = filterGsc(matches.putative, configs.gsc);
  const auto both = makeFilter("epipolar+gsc", configs);
  EXPECT_EQ(both->name(), "epipolar+gsc");
  const FilterResult result = both->apply(matches.putative);
  for (size_t m = 0; m < matches.putative.matches.size(); ++m) {
    EXPECT_EQ(result.keep[m], epipolar.keep[m] && gsc.keep[m]) << m;
    EXPECT_EQ(result.score[m], (epipolar.keep[m] ? 0 : 1) + (gsc.keep[m] ? 0 : 1)) << m;
  }
}

TEST(Factory, KnowsEveryNameAndRejectsOthers) {
  for (const std::string& name : filterNames()) EXPECT_EQ(makeFilter(name, {})->name(), name);
  EXPECT_THROW(makeFilter("sgc", {}), std::invalid_argument);
  EXPECT_THROW(makeFilter("gsc+", {}), std::invalid_argument);
  FilterConfigs bad;
  bad.gsc.max_histogram_distance = -1.0;
  EXPECT_THROW(makeFilter("gsc", bad), std::invalid_argument);
}

// ---- degenerate input: a defined result for every filter ----------------------------------------

PutativeMatches calibrated(PutativeMatches input) {
  input.F_right_left = rectifiedFundamentalMatrix();
  input.left_image_size = input.right_image_size = cv::Size(640, 480);
  return input;
}

PutativeMatches withMatches(const std::vector<std::pair<cv::Point2f, cv::Point2f>>& pairs) {
  PutativeMatches input;
  for (const auto& [left, right] : pairs) {
    const int index = static_cast<int>(input.matches.size());
    input.left_keypoints.emplace_back(left, 4.f, 10.f);
    input.right_keypoints.emplace_back(right, 4.f, 10.f);
    input.matches.emplace_back(index, index, 0.f);
  }
  return calibrated(input);
}

void expectDefinedForEveryFilter(const PutativeMatches& input, const std::string& what) {
  for (const std::string& name : filterNames()) {
    const FilterResult result = makeFilter(name, FilterConfigs())->apply(input);
    ASSERT_EQ(result.keep.size(), input.matches.size()) << name << ", " << what;
    ASSERT_EQ(result.score.size(), input.matches.size()) << name << ", " << what;
  }
}

TEST(DegenerateInput, EmptyInput) {
  const PutativeMatches input = calibrated(PutativeMatches());
  expectDefinedForEveryFilter(input, "empty");
}

TEST(DegenerateInput, SingleMatchIsKeptByGscWithNoEvidenceAgainstIt) {
  const PutativeMatches input = withMatches({{{10, 20}, {5, 20}}});
  expectDefinedForEveryFilter(input, "single match");
  EXPECT_EQ(filterGsc(input, GscConfig()).score[0], 0.0);
  EXPECT_EQ(filterRansac(input, RobustFitConfig()).keptCount(), 0u);  // needs 8 matches
}

TEST(DegenerateInput, DuplicatePointsAreLeftOutOfTheirOwnHistograms) {
  const PutativeMatches input = withMatches(
      {{{10, 20}, {5, 20}}, {{10, 20}, {5, 20}}, {{10, 20}, {5, 20}}, {{50, 20}, {45, 20}}});
  expectDefinedForEveryFilter(input, "duplicates");
  const GscHistograms duplicate = gscHistograms(input, 0);
  // The one distinct point, at polar angle 0 - 10 = -10 degrees from the orientation: sector 7.
  EXPECT_EQ(duplicate.left[7], 1.0);
  EXPECT_EQ(filterGsc(input, GscConfig()).keptCount(), 4u);
}

TEST(DegenerateInput, NanCoordinatesAreNeverKeptAndIgnoredByOthers) {
  const PutativeMatches clean = withMatches(
      {{{10, 20}, {5, 20}}, {{50, 60}, {45, 60}}, {{90, 30}, {85, 30}}, {{30, 90}, {25, 90}}});
  PutativeMatches input = clean;
  input.left_keypoints.emplace_back(cv::Point2f(NAN, 3.f), 4.f, 10.f);
  input.right_keypoints.emplace_back(cv::Point2f(7.f, 3.f), 4.f, 10.f);
  input.matches.emplace_back(4, 4, 0.f);
  expectDefinedForEveryFilter(input, "NaN");
  for (const std::string& name : filterNames()) {
    const FilterResult result = makeFilter(name, FilterConfigs())->apply(input);
    EXPECT_FALSE(result.keep[4]) << name;
    EXPECT_TRUE(std::isnan(result.score[4])) << name;
  }
  const FilterResult with_nan = filterGsc(input, GscConfig());
  const FilterResult without = filterGsc(clean, GscConfig());
  for (size_t m = 0; m < 4; ++m) EXPECT_EQ(with_nan.score[m], without.score[m]);
}

// ---- synthetic match generators -----------------------------------------------------------------

TEST(SyntheticMatches, InliersFollowTheSimilarityAndOutliersMakeTheirShare) {
  SyntheticMatchConfig config;
  config.inliers = 200;
  config.position_noise_px = 0.0;
  config.angle_noise_deg = 0.0;
  const LabelledMatches matches = syntheticMatches(config);
  ASSERT_EQ(matches.truth.size(), 286u);  // 200 / 0.7
  const double turn = config.rotation_deg * M_PI / 180.0;
  const cv::Point2f centre(320.f, 240.f);
  for (size_t m = 0; m < 200; ++m) {
    ASSERT_EQ(matches.truth[m], MatchTruth::kCorrect);
    const cv::Point2f d = matches.putative.left(m).pt - centre;
    const cv::Point2f expected(
        static_cast<float>(config.scale * (std::cos(turn) * d.x - std::sin(turn) * d.y)),
        static_cast<float>(config.scale * (std::sin(turn) * d.x + std::cos(turn) * d.y)));
    const cv::Point2f shift(15.f, 15.f);
    EXPECT_LT(cv::norm(matches.putative.right(m).pt - (centre + expected + shift)), 1e-3);
    const double turned = matches.putative.right(m).angle - matches.putative.left(m).angle;
    EXPECT_NEAR(std::remainder(turned - config.rotation_deg, 360.0), 0.0, 1e-3);
  }
  for (size_t m = 200; m < matches.truth.size(); ++m)
    EXPECT_EQ(matches.truth[m], MatchTruth::kWrong);
}

TEST(SyntheticMatches, MismatchesIndexTheirOwnKeypointsWhenKeypointsOutnumberMatches) {
  LabelledMatches matches = rectifiedPair(10, 5.0, 1);
  matches.putative.matches.resize(4);  // 10 keypoints per image, 4 matches
  matches.truth.resize(4);
  injectMismatches(&matches, 0.5, 2);
  ASSERT_EQ(matches.putative.matches.size(), 8u);
  for (size_t m = 4; m < 8; ++m) {
    EXPECT_EQ(matches.putative.matches[m].queryIdx, static_cast<int>(10 + m - 4));
    EXPECT_EQ(matches.putative.matches[m].trainIdx, static_cast<int>(10 + m - 4));
    EXPECT_EQ(matches.truth[m], MatchTruth::kWrong);
  }
}

TEST(SyntheticMatches, TilingKeepsARectifiedPairRectified) {
  const LabelledMatches matches = rectifiedPair(50, 12.0, 3);
  const LabelledMatches tiled = tileMatches(matches, 3, 2);
  ASSERT_EQ(tiled.truth.size(), 300u);
  EXPECT_EQ(tiled.putative.left_image_size, cv::Size(1920, 960));
  const FilterResult epipolar = filterEpipolar(tiled.putative, EpipolarConfig{0.01});
  EXPECT_EQ(epipolar.keptCount(), 300u);
  EXPECT_THROW(tileMatches(matches, 0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
