#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/gms.h"

namespace sift_hull {
namespace {

using PointMap = std::function<cv::Point2f(const cv::Point2f&)>;

/// Putative matches with known ground truth: which match is an inlier.
struct SyntheticMatches {
  PutativeMatches input;
  std::vector<bool> is_inlier;
};

void addMatch(const cv::Point2f& left, const cv::Point2f& right, PutativeMatches* input) {
  const int index = static_cast<int>(input->matches.size());
  input->left_keypoints.emplace_back(left, 5.0f);
  input->right_keypoints.emplace_back(right, 5.0f);
  input->matches.emplace_back(index, index, 100.0f);
}

/// `inlier_count` uniformly spread left points mapped by `map` (plus 0.5 px noise) to points
/// inside the right image, then outliers to random right points until they make up
/// `outlier_fraction` of all matches, shuffled.
SyntheticMatches makeSyntheticMatches(const PointMap& map, cv::Size left_size, cv::Size right_size,
                                      int inlier_count, double outlier_fraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> left_x(0.0f, left_size.width),
      left_y(0.0f, left_size.height);
  std::uniform_real_distribution<float> right_x(0.0f, right_size.width),
      right_y(0.0f, right_size.height);
  std::normal_distribution<float> noise(0.0f, 0.5f);
  const cv::Rect2f right_image(0.0f, 0.0f, right_size.width, right_size.height);
  std::vector<std::pair<cv::Point2f, cv::Point2f>> pairs;
  std::vector<bool> is_inlier;
  while (static_cast<int>(pairs.size()) < inlier_count) {
    const cv::Point2f left(left_x(rng), left_y(rng));
    const cv::Point2f right = map(left) + cv::Point2f(noise(rng), noise(rng));
    if (!right_image.contains(right)) continue;
    pairs.emplace_back(left, right);
    is_inlier.push_back(true);
  }
  const int outlier_count =
      static_cast<int>(std::lround(inlier_count * outlier_fraction / (1.0 - outlier_fraction)));
  for (int i = 0; i < outlier_count; ++i) {
    pairs.emplace_back(cv::Point2f(left_x(rng), left_y(rng)),
                       cv::Point2f(right_x(rng), right_y(rng)));
    is_inlier.push_back(false);
  }
  std::vector<size_t> order(pairs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);

  SyntheticMatches synthetic;
  synthetic.input.left_image_size = left_size;
  synthetic.input.right_image_size = right_size;
  for (size_t i : order) {
    addMatch(pairs[i].first, pairs[i].second, &synthetic.input);
    synthetic.is_inlier.push_back(is_inlier[i]);
  }
  return synthetic;
}

struct Rates {
  double inliers_kept = 0.0;
  double outliers_removed = 0.0;
};

Rates measure(const SyntheticMatches& synthetic, const FilterResult& result) {
  size_t inliers = 0, inliers_kept = 0, outliers = 0, outliers_removed = 0;
  for (size_t i = 0; i < synthetic.is_inlier.size(); ++i) {
    if (synthetic.is_inlier[i]) {
      ++inliers;
      inliers_kept += result.keep[i];
    } else {
      ++outliers;
      outliers_removed += !result.keep[i];
    }
  }
  return {static_cast<double>(inliers_kept) / inliers,
          static_cast<double>(outliers_removed) / outliers};
}

const cv::Size kVga(640, 480);

/// Turns by `degrees` and scales by `scale` about the centre of a 640x480 image, then shifts.
PointMap similarity(double degrees, double scale, cv::Point2f shift) {
  const double angle = degrees * CV_PI / 180.0;
  const double c = scale * std::cos(angle), s = scale * std::sin(angle);
  const cv::Point2f centre(320.0f, 240.0f);
  return [=](const cv::Point2f& p) {
    const cv::Point2f d = p - centre;
    return centre + shift +
           cv::Point2f(static_cast<float>(c * d.x - s * d.y),
                       static_cast<float>(s * d.x + c * d.y));
  };
}

/// Runs GMS and checks the result has one entry per match.
Rates filterAndMeasure(const SyntheticMatches& synthetic, const GmsConfig& config) {
  const FilterResult result = filterGms(synthetic.input, config);
  EXPECT_EQ(result.keep.size(), synthetic.input.matches.size());
  EXPECT_EQ(result.score.size(), synthetic.input.matches.size());
  return measure(synthetic, result);
}

TEST(Gms, KeepsInliersAndRemovesOutliersUnderASimilarity) {
  const SyntheticMatches synthetic =
      makeSyntheticMatches(similarity(10.0, 1.1, {15.0f, -10.0f}), kVga, kVga, 2000, 0.3, 1);
  const Rates rates = filterAndMeasure(synthetic, GmsConfig());
  // Measured: 0.9250 of the inliers kept, 0.9942 of the outliers removed (over seeds 100..129
  // the worst were 0.9115 and 0.9895).
  EXPECT_GE(rates.inliers_kept, 0.90);
  EXPECT_GE(rates.outliers_removed, 0.97);
}

TEST(Gms, KeepsInliersAndRemovesOutliersUnderAnAffineMap) {
  const PointMap affine = [](const cv::Point2f& p) {
    return cv::Point2f(0.95f * p.x + 0.08f * p.y + 12.0f, -0.05f * p.x + 1.05f * p.y + 5.0f);
  };
  const SyntheticMatches synthetic = makeSyntheticMatches(affine, kVga, kVga, 2000, 0.3, 2);
  const Rates rates = filterAndMeasure(synthetic, GmsConfig());
  // Measured: 0.9450 of the inliers kept, 0.9942 of the outliers removed.
  EXPECT_GE(rates.inliers_kept, 0.92);
  EXPECT_GE(rates.outliers_removed, 0.97);
}

TEST(Gms, KeptExactlyWhenScoreExceedsOne) {
  const SyntheticMatches synthetic =
      makeSyntheticMatches(similarity(5.0, 1.0, {0.0f, 0.0f}), kVga, kVga, 2000, 0.3, 3);
  const FilterResult result = filterGms(synthetic.input, GmsConfig());
  for (size_t i = 0; i < result.keep.size(); ++i) {
    EXPECT_EQ(result.keep[i] == 1, result.score[i] > 1.0) << "match " << i;
    EXPECT_GE(result.score[i], 0.0);
  }
  EXPECT_GT(result.keptCount(), 0u);
}

TEST(Gms, RotationBy90DegreesNeedsWithRotation) {
  // The right image is the left one turned 90 degrees clockwise: 480 wide, 640 high.
  const PointMap turn = [](const cv::Point2f& p) { return cv::Point2f(480.0f - p.y, p.x); };
  const SyntheticMatches synthetic =
      makeSyntheticMatches(turn, kVga, cv::Size(480, 640), 2000, 0.3, 4);
  GmsConfig config;
  const Rates without = filterAndMeasure(synthetic, config);
  config.with_rotation = true;
  const Rates with = filterAndMeasure(synthetic, config);
  // Measured: without rotation 0 inliers kept; with it 0.9835 kept and 0.9930 of the outliers
  // removed.
  EXPECT_LE(without.inliers_kept, 0.05);
  EXPECT_GE(with.inliers_kept, 0.95);
  EXPECT_GE(with.outliers_removed, 0.97);
}

TEST(Gms, ScaleByTwoWorksWithScale) {
  // The right image zooms into the centre of the left one: only its middle quarter is matched.
  const SyntheticMatches synthetic =
      makeSyntheticMatches(similarity(0.0, 2.0, {0.0f, 0.0f}), kVga, kVga, 2000, 0.3, 5);
  GmsConfig config;
  const Rates without = filterAndMeasure(synthetic, config);
  config.with_scale = true;
  const Rates with = filterAndMeasure(synthetic, config);
  // Measured: without scale 0.1645 of the inliers kept; with it 0.9945 kept and 0.9965 of the
  // outliers removed.
  EXPECT_LE(without.inliers_kept, 0.3);
  EXPECT_GE(with.inliers_kept, 0.97);
  EXPECT_GE(with.outliers_removed, 0.97);
}

TEST(Gms, EmptyInputGivesEmptyResult) {
  const FilterResult result = filterGms(PutativeMatches(), GmsConfig());
  EXPECT_TRUE(result.keep.empty());
  EXPECT_TRUE(result.score.empty());
}

TEST(Gms, OneMatchIsNotKept) {
  PutativeMatches input;
  input.left_image_size = input.right_image_size = kVga;
  addMatch({100.0f, 100.0f}, {110.0f, 95.0f}, &input);
  const FilterResult result = filterGms(input, GmsConfig());
  ASSERT_EQ(result.keep.size(), 1u);
  EXPECT_EQ(result.keep[0], 0);
  // Support 1 against tau = 6 * sqrt(1 / 9) = 2.
  EXPECT_NEAR(result.score[0], 0.5, 1e-12);
}

TEST(Gms, NonFiniteCoordinatesAreNeverKeptAndScoreNaN) {
  SyntheticMatches synthetic =
      makeSyntheticMatches(similarity(0.0, 1.0, {5.0f, 5.0f}), kVga, kVga, 2000, 0.3, 6);
  const size_t first_bad = synthetic.input.matches.size();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // Non-finite points placed on top of well supported inliers must not borrow their support.
  addMatch({nan, 200.0f}, {205.0f, 205.0f}, &synthetic.input);
  addMatch({200.0f, 200.0f}, {205.0f, inf}, &synthetic.input);
  addMatch({-inf, nan}, {nan, nan}, &synthetic.input);
  const FilterResult result = filterGms(synthetic.input, GmsConfig());
  ASSERT_EQ(result.keep.size(), first_bad + 3);
  for (size_t i = first_bad; i < result.keep.size(); ++i) {
    EXPECT_EQ(result.keep[i], 0);
    EXPECT_TRUE(std::isnan(result.score[i]));
  }
  synthetic.input.matches.resize(first_bad);
  const FilterResult clean = filterGms(synthetic.input, GmsConfig());
  for (size_t i = 0; i < first_bad; ++i) EXPECT_EQ(result.keep[i], clean.keep[i]);
}

TEST(Gms, PointsOutsideTheImageAreDroppedWithScoreZero) {
  SyntheticMatches synthetic =
      makeSyntheticMatches(similarity(0.0, 1.0, {5.0f, 5.0f}), kVga, kVga, 2000, 0.3, 7);
  const size_t first_outside = synthetic.input.matches.size();
  addMatch({-1.0f, 200.0f}, {4.0f, 205.0f}, &synthetic.input);
  addMatch({640.0f, 200.0f}, {645.0f, 205.0f}, &synthetic.input);
  addMatch({200.0f, 480.5f}, {205.0f, 485.5f}, &synthetic.input);
  addMatch({200.0f, 200.0f}, {205.0f, -3.0f}, &synthetic.input);
  addMatch({1e9f, -1e9f}, {-1e9f, 1e9f}, &synthetic.input);
  const FilterResult result = filterGms(synthetic.input, GmsConfig());
  ASSERT_EQ(result.keep.size(), first_outside + 5);
  for (size_t i = first_outside; i < result.keep.size(); ++i) {
    EXPECT_EQ(result.keep[i], 0) << "match " << i;
    EXPECT_EQ(result.score[i], 0.0) << "match " << i;
  }
  EXPECT_GE(measure(synthetic, result).inliers_kept, 0.90);
}

TEST(Gms, InvalidConfigurationThrows) {
  PutativeMatches input;
  input.left_image_size = input.right_image_size = kVga;
  addMatch({100.0f, 100.0f}, {110.0f, 95.0f}, &input);
  GmsConfig config;
  config.grid_cells = 2;
  EXPECT_THROW(filterGms(input, config), std::invalid_argument);
  EXPECT_THROW(filterGms(PutativeMatches(), config), std::invalid_argument);
  config = GmsConfig();
  config.threshold_factor = 0.0;
  EXPECT_THROW(filterGms(input, config), std::invalid_argument);
  config.threshold_factor = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(filterGms(input, config), std::invalid_argument);

  input.left_image_size = cv::Size(0, 480);
  EXPECT_THROW(filterGms(input, GmsConfig()), std::invalid_argument);
  input.left_image_size = kVga;
  input.right_image_size = cv::Size(640, -1);
  EXPECT_THROW(filterGms(input, GmsConfig()), std::invalid_argument);
  input.right_image_size = kVga;
  input.matches[0].trainIdx = 7;
  EXPECT_THROW(filterGms(input, GmsConfig()), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
