#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <stdexcept>
#include <vector>

#include "sift_hull/features/triangulation.h"

namespace sift_hull {
namespace {

/// A camera 2 m from the origin on the x-z plane, at `azimuth_deg`, looking at the origin.
PinholeCamera cameraAt(double azimuth_deg) {
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const double a = azimuth_deg * M_PI / 180.0;
  const Eigen::Vector3d centre(2.0 * std::sin(a), 0.0, -2.0 * std::cos(a));
  const Eigen::Vector3d z = -centre.normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Matrix3d R;  // rows: the camera axes in world coordinates
  R.row(0) = x.transpose();
  R.row(1) = z.cross(x).transpose();
  R.row(2) = z.transpose();
  return PinholeCamera::fromCentre(K, R, centre);
}

/// Matches of the projections of `points_W` in both cameras, one keypoint pair per point.
PutativeMatches matchesOf(const std::vector<Eigen::Vector3d>& points_W, const PinholeCamera& left,
                          const PinholeCamera& right) {
  PutativeMatches matches;
  for (size_t i = 0; i < points_W.size(); ++i) {
    const Eigen::Vector2d l = left.project(points_W[i]), r = right.project(points_W[i]);
    matches.left_keypoints.emplace_back(cv::Point2f(l.x(), l.y()), 2.0f);
    matches.right_keypoints.emplace_back(cv::Point2f(r.x(), r.y()), 2.0f);
    matches.matches.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.0f);
  }
  return matches;
}

TEST(TriangulateMatchesTest, KeptMatchesGiveTheirWorldPointsInOrder) {
  const PinholeCamera left = cameraAt(-10.0), right = cameraAt(10.0);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> coordinate(-0.3, 0.3);
  std::vector<Eigen::Vector3d> points_W;
  for (int i = 0; i < 50; ++i) {
    points_W.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  }
  const PutativeMatches matches = matchesOf(points_W, left, right);
  std::vector<uint8_t> keep(points_W.size(), 0);
  std::vector<Eigen::Vector3d> expected;
  for (size_t i = 0; i < keep.size(); i += 3) {
    keep[i] = 1;
    expected.push_back(points_W[i]);
  }
  const std::vector<Eigen::Vector3d> points = triangulateMatches(left, right, matches, keep);
  ASSERT_EQ(points.size(), expected.size());
  for (size_t i = 0; i < points.size(); ++i) {
    // Keypoints hold float pixels: a few micrometres at 2 m.
    EXPECT_LT((points[i] - expected[i]).norm(), 1e-4) << "point " << i;
  }
}

TEST(TriangulateMatchesTest, PointsBehindACameraAreLeftOut) {
  const PinholeCamera left = cameraAt(-10.0), right = cameraAt(10.0);
  const std::vector<Eigen::Vector3d> in_front = {{0.1, 0.0, 0.0}, {0.0, 0.1, 0.2}};
  PutativeMatches matches = matchesOf(in_front, left, right);
  // A point behind both cameras (they stand near z = -2 and look towards +z) projects to pixels
  // whose rays, continued backwards, meet there.
  const Eigen::Vector3d behind(0.0, 0.05, -5.0);
  ASSERT_LT(left.depth(behind), 0.0);
  ASSERT_LT(right.depth(behind), 0.0);
  const Eigen::Vector2d l = left.project(behind), r = right.project(behind);
  matches.left_keypoints.emplace_back(cv::Point2f(l.x(), l.y()), 2.0f);
  matches.right_keypoints.emplace_back(cv::Point2f(r.x(), r.y()), 2.0f);
  matches.matches.emplace_back(2, 2, 0.0f);
  const std::vector<Eigen::Vector3d> points =
      triangulateMatches(left, right, matches, std::vector<uint8_t>(3, 1));
  ASSERT_EQ(points.size(), 2u);
  EXPECT_LT((points[0] - in_front[0]).norm(), 1e-4);
  EXPECT_LT((points[1] - in_front[1]).norm(), 1e-4);
}

TEST(TriangulateMatchesTest, RefusesFlagsThatDoNotMatchTheMatches) {
  const PinholeCamera left = cameraAt(-10.0), right = cameraAt(10.0);
  const PutativeMatches matches = matchesOf({{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}}, left, right);
  EXPECT_THROW(triangulateMatches(left, right, matches, {1}), std::invalid_argument);
  EXPECT_TRUE(triangulateMatches(left, right, matches, {0, 0}).empty());
}

}  // namespace
}  // namespace sift_hull
