// Lens distortion in the camera model: OpenCV's radial-tangential model and its inverse, raw and
// ideal pixels, the bounds of the undistorted image, and fold-over detection.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/geometry/distortion.h"

namespace sift_hull {
namespace {

const LensDistortion kBarrel{-0.28, 0.09, 0.0012, -0.0007, -0.01};

PinholeCamera camera640(const LensDistortion& distortion) {
  Eigen::Matrix3d K;
  K << 520.0, 0.0, 319.5, 0.0, 515.0, 239.5, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  return PinholeCamera(K, R, Eigen::Vector3d(0.1, -0.2, 3.0)).withDistortion(distortion);
}

TEST(Distortion, MatchesOpenCvProjectPoints) {
  const PinholeCamera camera = camera640(kBarrel);
  std::vector<cv::Point3d> points;
  for (double x : {-0.6, 0.0, 0.5}) {
    for (double y : {-0.4, 0.1, 0.45}) points.emplace_back(x, y, 0.2 * x);
  }
  cv::Mat K, R, rvec,
      D = (cv::Mat_<double>(1, 5) << kBarrel.k1, kBarrel.k2, kBarrel.p1, kBarrel.p2, kBarrel.k3);
  cv::eigen2cv(Eigen::Matrix3d(camera.K()), K);
  cv::eigen2cv(Eigen::Matrix3d(camera.R()), R);
  cv::Rodrigues(R, rvec);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << camera.t().x(), camera.t().y(), camera.t().z());
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, rvec, tvec, K, D, expected);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d pixel = camera.project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(pixel.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), expected[i].y, 1e-9);
  }
}

TEST(Distortion, UndistortInvertsDistortOverTheImage) {
  const PinholeCamera camera = camera640(kBarrel);
  double worst = 0.0;
  for (double u = -0.5; u <= 639.5; u += 16.0) {
    for (double v = -0.5; v <= 479.5; v += 16.0) {
      const std::optional<Eigen::Vector2d> ideal = camera.undistortPixel({u, v});
      ASSERT_TRUE(ideal.has_value()) << u << ", " << v;
      worst = std::max(worst, (camera.distortPixel(*ideal) - Eigen::Vector2d(u, v)).norm());
    }
  }
  EXPECT_LT(worst, 1e-8);
}

TEST(Distortion, RayAndBackProjectionUseRawPixels) {
  const PinholeCamera camera = camera640(kBarrel);
  const Eigen::Vector3d X_W(0.4, -0.3, 0.2);
  const Eigen::Vector2d raw = camera.project(X_W);
  const Eigen::Vector2d ideal = camera.projectIdeal(X_W);
  EXPECT_GT((raw - ideal).norm(), 1.0);  // the lens moves this point by pixels
  EXPECT_LT((camera.backProject(raw, camera.depth(X_W)) - X_W).norm(), 1e-9);
  const Eigen::Vector3d ray = camera.rayDirection(raw);
  EXPECT_LT(ray.cross((X_W - camera.centre()).normalized()).norm(), 1e-9);
  EXPECT_LT((camera.undistortPixel(raw).value() - ideal).norm(), 1e-8);
}

TEST(Distortion, JacobianMatchesFiniteDifferences) {
  const Eigen::Vector2d x(0.31, -0.22);
  const Eigen::Matrix2d J = distortionJacobian(kBarrel, x);
  const double h = 1e-6;
  for (int axis = 0; axis < 2; ++axis) {
    const Eigen::Vector2d step = Eigen::Vector2d::Unit(axis) * h;
    const Eigen::Vector2d numeric =
        (distortNormalised(kBarrel, x + step) - distortNormalised(kBarrel, x - step)) / (2 * h);
    EXPECT_LT((J.col(axis) - numeric).norm(), 1e-7);
  }
}

TEST(Distortion, UndistortedBoundsHoldTheUndistortedImage) {
  const PinholeCamera camera = camera640(kBarrel);
  const auto [low, high] = camera.undistortedBounds({-0.5, -0.5}, {639.5, 479.5});
  // Barrel distortion: the ideal image is larger than the raw one, most at the corners.
  EXPECT_LT(low.x(), -0.5);
  EXPECT_GT(high.y(), 479.5);
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(639.5, 479.5), Eigen::Vector2d(319.5, -0.5)}) {
    const Eigen::Vector2d ideal = camera.undistortPixel(corner).value();
    EXPECT_TRUE((ideal.array() >= low.array() - 1e-9).all() &&
                (ideal.array() <= high.array() + 1e-9).all());
  }
  const PinholeCamera pinhole = camera640({});
  const auto [same_low, same_high] = pinhole.undistortedBounds({-0.5, -0.5}, {639.5, 479.5});
  EXPECT_EQ(same_low, Eigen::Vector2d(-0.5, -0.5));
  EXPECT_EQ(same_high, Eigen::Vector2d(639.5, 479.5));
}

TEST(Distortion, FoldOverIsDetected) {
  EXPECT_TRUE(camera640(kBarrel).distortionInvertibleOver({-0.5, -0.5}, {639.5, 479.5}));
  // k1 = -1.5 folds the model over at r^2 = 1/4.5, well inside this image's corners (r^2 ~ 0.6).
  const PinholeCamera folded = camera640({-1.5, 0.0, 0.0, 0.0, 0.0});
  EXPECT_FALSE(folded.distortionInvertibleOver({-0.5, -0.5}, {639.5, 479.5}));
  EXPECT_FALSE(folded.undistortPixel({-0.5, -0.5}).has_value());
}

const LensDistortion kRational{0.6, -0.2, 0.0008, -0.0005, 0.03, 0.9, -0.15, 0.04};

TEST(Distortion, RationalModelMatchesOpenCvProjectPoints) {
  const PinholeCamera camera = camera640(kRational);
  const Eigen::Matrix3d K = camera.K(), R = camera.R();
  cv::Mat K_cv, R_cv, rvec;
  cv::eigen2cv(K, K_cv);
  cv::eigen2cv(R, R_cv);
  cv::Rodrigues(R_cv, rvec);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << camera.t().x(), camera.t().y(), camera.t().z());
  const LensDistortion& d = kRational;
  const cv::Mat D = (cv::Mat_<double>(1, 8) << d.k1, d.k2, d.p1, d.p2, d.k3, d.k4, d.k5, d.k6);
  const std::vector<cv::Point3d> points = {{-0.6, -0.4, 0.1}, {0.0, 0.1, 0.0}, {0.5, 0.45, -0.2}};
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, rvec, tvec, K_cv, D, expected);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d pixel = camera.project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(pixel.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), expected[i].y, 1e-9);
    const Eigen::Vector2d ideal = camera.undistortPixel(pixel).value();
    EXPECT_LT((ideal - camera.projectIdeal({points[i].x, points[i].y, points[i].z})).norm(), 1e-8);
  }
}

TEST(Distortion, RationalJacobianMatchesFiniteDifferences) {
  const Eigen::Vector2d x(0.31, -0.22);
  const Eigen::Matrix2d J = distortionJacobian(kRational, x);
  const double h = 1e-6;
  for (int axis = 0; axis < 2; ++axis) {
    const Eigen::Vector2d step = Eigen::Vector2d::Unit(axis) * h;
    const Eigen::Vector2d numeric =
        (distortNormalised(kRational, x + step) - distortNormalised(kRational, x - step)) / (2 * h);
    EXPECT_LT((J.col(axis) - numeric).norm(), 1e-7);
  }
  EXPECT_TRUE(kRational.rational());
  EXPECT_FALSE(LensDistortion{}.rational());
  EXPECT_FALSE((LensDistortion{0, 0, 0, 0, 0, 0, 0.1, 0}).isZero());
}

TEST(Distortion, FisheyeJacobianMatchesFiniteDifferencesAndZeroIsNotAPinhole) {
  LensDistortion fisheye{0.05, -0.01, 0.0, 0.0, 0.002, -0.0004};
  fisheye.fisheye = true;
  for (const Eigen::Vector2d& x :
       {Eigen::Vector2d(0.31, -0.22), Eigen::Vector2d(1.2, 0.7), Eigen::Vector2d(1e-9, 0.0)}) {
    const Eigen::Matrix2d J = distortionJacobian(fisheye, x);
    const double h = 1e-6;
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector2d step = Eigen::Vector2d::Unit(axis) * h;
      const Eigen::Vector2d numeric =
          (distortNormalised(fisheye, x + step) - distortNormalised(fisheye, x - step)) / (2 * h);
      EXPECT_LT((J.col(axis) - numeric).norm(), 1e-6) << x.transpose();
    }
    EXPECT_LT((undistortNormalised(fisheye, distortNormalised(fisheye, x)).value() - x).norm(),
              1e-10);
  }
  LensDistortion equidistant;
  equidistant.fisheye = true;  // theta_d = theta: the equidistant projection
  EXPECT_FALSE(equidistant.isZero());
  EXPECT_NEAR(distortNormalised(equidistant, {1.0, 0.0}).x(), M_PI / 4.0, 1e-15);
  LensDistortion tangential = fisheye;
  tangential.p1 = 0.001;
  EXPECT_THROW(validate(tangential), std::invalid_argument);
}

TEST(Distortion, NonFiniteCoefficientsAreRefused) {
  EXPECT_THROW(camera640({0.0, 0.0, 0.0, 0.0, 0.0, 0.0, NAN, 0.0}), std::invalid_argument);
  EXPECT_THROW(camera640({NAN, 0.0, 0.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(camera640({0.0, 0.0, 0.0, INFINITY, 0.0}), std::invalid_argument);
}

TEST(Distortion, NoDistortionIsTheIdealPinhole) {
  const PinholeCamera camera = camera640({});
  EXPECT_FALSE(camera.distorted());
  const Eigen::Vector3d X_W(0.2, 0.1, -0.1);
  EXPECT_EQ(camera.project(X_W), camera.projectIdeal(X_W));
  EXPECT_EQ(camera.undistortPixel({12.0, 34.0}).value(), Eigen::Vector2d(12.0, 34.0));
}

}  // namespace
}  // namespace sift_hull
