#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using MatchSet = std::set<std::pair<int, int>>;

MatchSet asSet(const std::vector<cv::DMatch>& matches) {
  MatchSet pairs;
  for (const cv::DMatch& match : matches) pairs.emplace(match.queryIdx, match.trainIdx);
  return pairs;
}

/// Two neighbouring views (30 degrees apart on the ring) of the default scene at 320x240, and
/// their SIFT features, shared by the tests below.
class TwoViews : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (int i = 0; i < 2; ++i) {
      images_[i] = renderSceneView(test::smallRing(), i).image;
      features_[i] = detectSift(images_[i]);
    }
  }
  static cv::Mat images_[2];
  static Features features_[2];
};
cv::Mat TwoViews::images_[2];
Features TwoViews::features_[2];

// ---- detectSift ---------------------------------------------------------------------------------

TEST_F(TwoViews, DetectsManyKeypointsWithOneDescriptorRowEach) {
  for (const Features& features : features_) {
    std::cout << features.keypoints.size() << " keypoints\n";
    EXPECT_GT(features.keypoints.size(), 200u);  // measured: 371 and 369
    EXPECT_EQ(features.descriptors.type(), CV_32FC1);
    EXPECT_EQ(features.descriptors.cols, 128);
    EXPECT_EQ(features.descriptors.rows, static_cast<int>(features.keypoints.size()));
  }
}

TEST_F(TwoViews, ColourAndGreyImagesGiveTheSameFeatures) {
  cv::Mat grey;
  cv::cvtColor(images_[0], grey, cv::COLOR_BGR2GRAY);
  const Features from_grey = detectSift(grey);
  ASSERT_EQ(from_grey.keypoints.size(), features_[0].keypoints.size());
  for (size_t i = 0; i < from_grey.keypoints.size(); ++i) {
    const cv::KeyPoint &a = from_grey.keypoints[i], &b = features_[0].keypoints[i];
    EXPECT_EQ(a.pt, b.pt) << i;
    EXPECT_EQ(a.angle, b.angle) << i;
    EXPECT_EQ(a.size, b.size) << i;
  }
  EXPECT_EQ(cv::norm(from_grey.descriptors, features_[0].descriptors, cv::NORM_INF), 0.0);
}

TEST_F(TwoViews, MaxFeaturesCapsTheCount) {
  SiftConfig config;
  config.max_features = 50;
  const Features capped = detectSift(images_[0], config);
  EXPECT_LE(capped.keypoints.size(), 50u);
  EXPECT_GE(capped.keypoints.size(), 45u);
  EXPECT_EQ(capped.descriptors.rows, static_cast<int>(capped.keypoints.size()));
}

TEST(DetectSift, RejectsBadConfigsAndEmptyImages) {
  const cv::Mat image(64, 64, CV_8UC1, cv::Scalar(128));
  std::vector<SiftConfig> bad(5);
  bad[0].max_features = -1;
  bad[1].octave_layers = 0;
  bad[2].contrast_threshold = -0.01;
  bad[3].edge_threshold = 0.0;
  bad[4].sigma_px = 0.0;
  const char* fields[] = {"max_features", "octave_layers", "contrast_threshold", "edge_threshold",
                          "sigma_px"};
  for (size_t i = 0; i < bad.size(); ++i) {
    try {
      detectSift(image, bad[i]);
      ADD_FAILURE() << "expected an error for " << fields[i];
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fields[i]), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(validate(SiftConfig()));
  EXPECT_THROW(detectSift(cv::Mat()), std::invalid_argument);
}

// ---- orientation convention ---------------------------------------------------------------------

/// Rotation by `degrees` about the image centre, in image coordinates (x right, y down) in the
/// x-towards-y sense: the x axis turns towards the y axis for positive angles.
cv::Mat rotationAboutCentre(cv::Size size, double degrees) {
  const double c = std::cos(degrees * M_PI / 180.0), s = std::sin(degrees * M_PI / 180.0);
  const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
  return (cv::Mat_<double>(2, 3) << c, -s, cx - c * cx + s * cy, s, c, cy - s * cx - c * cy);
}

/// Signed difference a - b of two angles in degrees, in [-180, 180).
double angleDifference(double a, double b) {
  double difference = std::fmod(a - b, 360.0);
  if (difference < -180.0) difference += 360.0;
  if (difference >= 180.0) difference -= 360.0;
  return difference;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

/// Keypoint angle changes (right minus left, minus `degrees`) of the matches whose positions agree
/// with `rotation` within 2 px.
std::vector<double> angleErrors(const PutativeMatches& input, const cv::Mat& rotation,
                                double degrees) {
  std::vector<double> errors;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    const cv::Point2f l = input.left(m).pt, r = input.right(m).pt;
    const cv::Matx23d A = rotation;
    const cv::Point2d mapped(A(0, 0) * l.x + A(0, 1) * l.y + A(0, 2),
                             A(1, 0) * l.x + A(1, 1) * l.y + A(1, 2));
    if (cv::norm(mapped - cv::Point2d(r)) > 2.0) continue;
    errors.push_back(angleDifference(input.right(m).angle - input.left(m).angle, degrees));
  }
  return errors;
}

class KeypointAngle : public TwoViews, public ::testing::WithParamInterface<double> {};

TEST_P(KeypointAngle, TurnsWithTheImageContentInTheXTowardsYSense) {
  const double degrees = GetParam();
  const cv::Mat rotation = rotationAboutCentre(images_[0].size(), degrees);
  cv::Mat rotated;
  cv::warpAffine(images_[0], rotated, rotation, images_[0].size());
  const PutativeMatches input = matchImages(images_[0], rotated, SiftConfig(), MatchConfig());
  const std::vector<double> errors = angleErrors(input, rotation, degrees);
  std::cout << errors.size() << " of " << input.matches.size()
            << " matches agree with the rotation; median angle error " << median(errors)
            << " deg\n";
  ASSERT_GT(errors.size(), 100u);  // measured: 286 of 288 at 30 degrees
  // The opposite convention would give an error of -2 * degrees.
  EXPECT_LT(std::abs(median(errors)), 3.0);
}

INSTANTIATE_TEST_SUITE_P(Rotations, KeypointAngle, ::testing::Values(30.0, -60.0, 135.0));

// ---- matchDescriptors ---------------------------------------------------------------------------

std::vector<cv::DMatch> matchWith(const Features& left, const Features& right, double ratio,
                                  bool cross_check = false) {
  MatchConfig config;
  config.ratio = ratio;
  config.cross_check = cross_check;
  return matchDescriptors(left.descriptors, right.descriptors, config);
}

TEST_F(TwoViews, RatioTestIsMonotone) {
  const std::vector<cv::DMatch> strict = matchWith(features_[0], features_[1], 0.6);
  const std::vector<cv::DMatch> loose = matchWith(features_[0], features_[1], 0.8);
  const std::vector<cv::DMatch> off = matchWith(features_[0], features_[1], 1.0);
  std::cout << strict.size() << " < " << loose.size() << " < " << off.size() << " matches\n";
  EXPECT_GT(strict.size(), 20u);
  EXPECT_LT(strict.size(), loose.size());
  EXPECT_LT(loose.size(), off.size());
  EXPECT_EQ(off.size(), features_[0].keypoints.size());  // every left point has a neighbour
  const MatchSet loose_set = asSet(loose), off_set = asSet(off);
  for (const auto& pair : asSet(strict)) EXPECT_TRUE(loose_set.count(pair));
  for (const auto& pair : loose_set) EXPECT_TRUE(off_set.count(pair));
}

/// All pairwise Euclidean distances, left descriptors by rows, right ones by columns.
cv::Mat distanceMatrix(const cv::Mat& left, const cv::Mat& right) {
  cv::Mat distances(left.rows, right.rows, CV_64FC1);
  for (int i = 0; i < left.rows; ++i) {
    for (int j = 0; j < right.rows; ++j) {
      distances.at<double>(i, j) = cv::norm(left.row(i), right.row(j), cv::NORM_L2);
    }
  }
  return distances;
}

/// Mutual nearest neighbours found by brute force.
MatchSet mutualNearest(const cv::Mat& distances) {
  std::vector<int> nearest_right(distances.rows), nearest_left(distances.cols);
  cv::Point where;
  for (int i = 0; i < distances.rows; ++i) {
    cv::minMaxLoc(distances.row(i), nullptr, nullptr, &where);
    nearest_right[i] = where.x;
  }
  for (int j = 0; j < distances.cols; ++j) {
    cv::minMaxLoc(distances.col(j), nullptr, nullptr, &where);
    nearest_left[j] = where.y;
  }
  MatchSet mutual;
  for (int i = 0; i < distances.rows; ++i) {
    if (nearest_left[nearest_right[i]] == i) mutual.emplace(i, nearest_right[i]);
  }
  return mutual;
}

TEST_F(TwoViews, CrossCheckKeepsExactlyTheMutualNearestNeighbours) {
  const cv::Mat distances = distanceMatrix(features_[0].descriptors, features_[1].descriptors);
  const MatchSet mutual = mutualNearest(distances);
  const MatchSet checked = asSet(matchWith(features_[0], features_[1], 1.0, true));
  std::cout << checked.size() << " mutual nearest neighbours\n";
  EXPECT_GT(checked.size(), 50u);
  EXPECT_LT(checked.size(), features_[0].keypoints.size());
  EXPECT_EQ(checked, mutual);
  // With the ratio test on, cross-checking keeps the mutual ones among the ratio test's matches.
  MatchSet expected;
  for (const auto& pair : asSet(matchWith(features_[0], features_[1], 0.8))) {
    if (mutual.count(pair)) expected.insert(pair);
  }
  EXPECT_EQ(asSet(matchWith(features_[0], features_[1], 0.8, true)), expected);
}

TEST_F(TwoViews, MaxDescriptorDistanceDropsTheFartherMatches) {
  const std::vector<cv::DMatch> all = matchWith(features_[0], features_[1], 0.8);
  std::vector<float> distances;
  for (const cv::DMatch& match : all) distances.push_back(match.distance);
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  MatchConfig config;
  config.max_descriptor_distance = distances[distances.size() / 2];
  const std::vector<cv::DMatch> near =
      matchDescriptors(features_[0].descriptors, features_[1].descriptors, config);
  MatchSet expected;
  for (const cv::DMatch& match : all) {
    if (match.distance <= config.max_descriptor_distance)
      expected.emplace(match.queryIdx, match.trainIdx);
  }
  EXPECT_LT(near.size(), all.size());
  EXPECT_GE(near.size(), all.size() / 2);
  EXPECT_EQ(asSet(near), expected);
  for (const cv::DMatch& match : near) EXPECT_LE(match.distance, config.max_descriptor_distance);
}

TEST_F(TwoViews, FlannAgreesWithBruteForceOnMostMatches) {
  MatchConfig config;
  const MatchSet exact =
      asSet(matchDescriptors(features_[0].descriptors, features_[1].descriptors, config));
  config.backend = "flann";
  const MatchSet approximate =
      asSet(matchDescriptors(features_[0].descriptors, features_[1].descriptors, config));
  size_t shared = 0;
  for (const auto& pair : approximate) shared += exact.count(pair);
  std::cout << shared << " of " << exact.size() << " brute-force matches also found by flann ("
            << approximate.size() << ")\n";
  EXPECT_GE(shared, 0.9 * exact.size());  // measured: 140 of 141
}

TEST_F(TwoViews, EmptyDescriptorSetsGiveNoMatches) {
  const cv::Mat none(0, 128, CV_32FC1);
  const MatchConfig config;
  EXPECT_TRUE(matchDescriptors(none, features_[1].descriptors, config).empty());
  EXPECT_TRUE(matchDescriptors(features_[0].descriptors, none, config).empty());
  EXPECT_TRUE(matchDescriptors(cv::Mat(), cv::Mat(), config).empty());
  MatchConfig flann = config;
  flann.backend = "flann";
  EXPECT_TRUE(matchDescriptors(none, features_[1].descriptors, flann).empty());
}

TEST(MatchDescriptors, RejectsInvalidConfigs) {
  const cv::Mat descriptors(4, 128, CV_32FC1, cv::Scalar(1.0f));
  std::vector<MatchConfig> bad(5);
  bad[0].ratio = 0.0;
  bad[1].ratio = -0.5;
  bad[2].max_descriptor_distance = std::nan("");  // 0 is no limit (the default)
  bad[3].max_descriptor_distance = -1.0;
  bad[4].backend = "kd-tree";
  for (const MatchConfig& config : bad) {
    EXPECT_THROW(validate(config), std::invalid_argument);
    EXPECT_THROW(matchDescriptors(descriptors, descriptors, config), std::invalid_argument);
  }
  EXPECT_NO_THROW(validate(MatchConfig()));
}

TEST_F(TwoViews, MatchImagesFillsSizesAndKeypoints) {
  const cv::Mat right = images_[1](cv::Rect(0, 0, 300, 200)).clone();
  const PutativeMatches input = matchImages(images_[0], right, SiftConfig(), MatchConfig());
  EXPECT_EQ(input.left_image_size, images_[0].size());
  EXPECT_EQ(input.right_image_size, cv::Size(300, 200));
  ASSERT_EQ(input.left_keypoints.size(), features_[0].keypoints.size());
  EXPECT_EQ(input.right_keypoints.size(), detectSift(right).keypoints.size());
  for (size_t i = 0; i < input.left_keypoints.size(); ++i) {
    EXPECT_EQ(input.left_keypoints[i].pt, features_[0].keypoints[i].pt);
  }
  EXPECT_GT(input.matches.size(), 50u);
  for (const cv::DMatch& match : input.matches) {
    ASSERT_LT(static_cast<size_t>(match.queryIdx), input.left_keypoints.size());
    ASSERT_LT(static_cast<size_t>(match.trainIdx), input.right_keypoints.size());
  }
  EXPECT_FALSE(input.F_right_left.has_value());
}

TEST(RectifiedFundamentalMatrix, AcceptsPointsOnTheSameRowOnly) {
  const Eigen::Matrix3d F = rectifiedFundamentalMatrix();
  const Eigen::Vector3d left(10.0, 20.0, 1.0);
  EXPECT_EQ(Eigen::Vector3d(3.0, 20.0, 1.0).dot(F * left), 0.0);
  EXPECT_NE(Eigen::Vector3d(10.0, 21.0, 1.0).dot(F * left), 0.0);
}

}  // namespace
}  // namespace sift_hull
