// A synthetic two-view scene shared by test_two_view_models and test_vote_ransac: two cameras
// with an exact F, projections of a box of points with noise, keypoint angles and sizes, and
// random mismatches.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/two_view_models.h"
#include "sift_hull/synthetic/synthetic_matches.h"

namespace sift_hull {
namespace test {

// ---- a synthetic two-view scene ----------------------------------------------------------------

/// Two cameras looking at a box of points 4 to 6 m away, the right one 0.6 m aside, turned and
/// rolled; F_right_left is exact.
struct TwoCameras {
  Eigen::Matrix3d K, R;  ///< X_right = R X_left + t
  Eigen::Vector3d t;
  Eigen::Matrix3d F() const {
    Eigen::Matrix3d tx;
    tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
    return K.inverse().transpose() * tx * R * K.inverse();
  }
};

inline TwoCameras twoCameras() {
  TwoCameras c;
  c.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  c.R = (Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(-0.12, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
  c.t = Eigen::Vector3d(-0.6, 0.05, 0.1);
  return c;
}

/// `inliers` projections of random points of the box (keypoint angles turned by the roll, sizes
/// scaled by the depth ratio, with noise), then random mismatches to make `outliers` of all.
inline LabelledMatches sceneMatches(size_t inliers, double outliers, unsigned seed,
                                    double noise_px) {
  const TwoCameras c = twoCameras();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> x(-1.5, 1.5), y(-1.0, 1.0), z(4.0, 6.0), angle(0, 360),
      size(2.0, 12.0);
  std::normal_distribution<double> noise(0.0, noise_px), angle_noise(0.0, 3.0);
  LabelledMatches out;
  PutativeMatches& p = out.putative;
  p.left_image_size = p.right_image_size = cv::Size(640, 480);
  const double roll_deg = 0.25 * 180.0 / M_PI;
  while (out.truth.size() < inliers) {
    const Eigen::Vector3d X(x(random), y(random), z(random)), Xr = c.R * X + c.t;
    const Eigen::Vector2d l = (c.K * X).hnormalized(), r = (c.K * Xr).hnormalized();
    if (r.x() < 0 || r.x() >= 640 || r.y() < 0 || r.y() >= 480) continue;
    const double a = angle(random), s = size(random);
    p.left_keypoints.emplace_back(
        cv::Point2f(float(l.x() + noise(random)), float(l.y() + noise(random))), float(s),
        float(a));
    p.right_keypoints.emplace_back(
        cv::Point2f(float(r.x() + noise(random)), float(r.y() + noise(random))),
        float(s * X.z() / Xr.z()), float(std::fmod(a + roll_deg + angle_noise(random) + 360, 360)));
    p.matches.emplace_back(int(out.truth.size()), int(out.truth.size()), 0.f);
    out.truth.push_back(MatchTruth::kCorrect);
  }
  injectMismatches(&out, outliers, seed + 1);
  return out;
}

/// The putatives' keypoint positions as point pairs, in match order.
inline PointPairs pairsOf(const PutativeMatches& p) {
  PointPairs pairs;
  for (size_t m = 0; m < p.matches.size(); ++m) {
    pairs.push(p.left(m).pt.x, p.left(m).pt.y, p.right(m).pt.x, p.right(m).pt.y);
  }
  return pairs;
}

}  // namespace test
}  // namespace sift_hull
