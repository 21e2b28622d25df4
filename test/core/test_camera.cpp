#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {
namespace {

Eigen::Matrix3d exampleK() {
  Eigen::Matrix3d K;
  K << 812.5, 0.7, 321.3, 0.0, 798.25, 238.9, 0.0, 0.0, 1.0;
  return K;
}

Eigen::Matrix3d randomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*rng), normal(*rng), normal(*rng), normal(*rng))
      .normalized()
      .toRotationMatrix();
}

/// Focal lengths 300..3000 px, a small skew and a principal point anywhere in a 640x480 image.
Eigen::Matrix3d randomK(std::mt19937* rng) {
  std::uniform_real_distribution<double> focal(300.0, 3000.0), unit(0.0, 1.0);
  Eigen::Matrix3d K;
  K << focal(*rng), unit(*rng) - 0.5, 640.0 * unit(*rng), 0.0, focal(*rng), 480.0 * unit(*rng), 0.0,
      0.0, 1.0;
  return K;
}

/// A camera with a random K at distance 3..5 from the origin looking roughly at it.
PinholeCamera randomCamera(std::mt19937* rng) {
  std::uniform_real_distribution<double> angle(-0.2, 0.2);
  const Eigen::Matrix3d R = randomRotation(rng);
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(angle(*rng), Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(angle(*rng), Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
  const double distance = std::uniform_real_distribution<double>(3.0, 5.0)(*rng);
  const Eigen::Vector3d centre = -distance * R.row(2).transpose();
  return PinholeCamera::fromCentre(randomK(rng), tilt * R, centre);
}

Eigen::Vector3d randomPoint(std::mt19937* rng) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  return {coordinate(*rng), coordinate(*rng), coordinate(*rng)};
}

TEST(Camera, TriangulationRecoversPointsInFrontOfBothCameras) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const PinholeCamera a = randomCamera(&rng), b = randomCamera(&rng);
    const Eigen::Vector3d X = randomPoint(&rng);
    const std::optional<Eigen::Vector3d> found = triangulate(a, b, a.project(X), b.project(X));
    ASSERT_TRUE(found.has_value());
    EXPECT_LT((*found - X).norm(), 1e-6);
  }
  // A point behind one camera is refused.
  const PinholeCamera a = randomCamera(&rng);
  // Turned half round its y axis, ten units ahead of `a`: it looks back, past the point.
  const Eigen::Matrix3d turned = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal() * a.R();
  const PinholeCamera behind =
      PinholeCamera::fromCentre(a.K(), turned, a.centre() + 10.0 * a.opticalAxis());
  const Eigen::Vector3d X = a.centre() + 12.0 * a.opticalAxis();  // behind `behind`
  EXPECT_FALSE(triangulate(a, behind, a.project(X), behind.project(X)).has_value());
}

TEST(Camera, ProjectBackProjectRoundTrip) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const PinholeCamera camera = randomCamera(&rng);
    const Eigen::Vector3d X = randomPoint(&rng);
    ASSERT_GT(camera.depth(X), 0.0);
    const Eigen::Vector2d pixel = camera.project(X);
    EXPECT_LT((camera.backProject(pixel, camera.depth(X)) - X).norm(), 1e-9);
    const Eigen::Vector3d ray = camera.rayDirection(pixel);
    const Eigen::Vector3d to_point = (X - camera.centre()).normalized();
    EXPECT_NEAR(ray.dot(to_point), 1.0, 1e-12);
  }
}

TEST(Camera, CentreFormAndMiddleburyFormAgree) {
  std::mt19937 rng(11);
  const Eigen::Matrix3d R = randomRotation(&rng);
  const Eigen::Vector3d centre(0.3, -1.2, 2.5);
  const PinholeCamera paper = PinholeCamera::fromCentre(exampleK(), R, centre);
  EXPECT_LT((paper.centre() - centre).norm(), 1e-12);
  const PinholeCamera middlebury(exampleK(), R, paper.t());
  EXPECT_LT((middlebury.t() + R * centre).norm(), 1e-12);
  EXPECT_LT((middlebury.projectionMatrix() - paper.projectionMatrix()).norm(), 1e-9);
  EXPECT_NEAR(paper.depth(centre + paper.opticalAxis()), 1.0, 1e-12);
}

TEST(Camera, ProjectionMatrixDecompositionRecoversKRt) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    const PinholeCamera camera = randomCamera(&rng);
    const double scale = (trial % 2 ? -1.0 : 1.0) * (0.01 + trial);  // any non-zero scale
    const PinholeCamera decomposed =
        PinholeCamera::fromProjection(scale * camera.projectionMatrix());
    EXPECT_LT((decomposed.K() - camera.K()).norm(), 1e-9 * camera.K().norm());
    EXPECT_LT((decomposed.R() - camera.R()).norm(), 1e-9);
    EXPECT_LT((decomposed.t() - camera.t()).norm(), 1e-9);
    EXPECT_NEAR(decomposed.R().determinant(), 1.0, 1e-12);
    EXPECT_GT(decomposed.K()(0, 0), 0.0);
    EXPECT_GT(decomposed.K()(1, 1), 0.0);
  }
}

TEST(Camera, TheNegatedCameraProjectsAlikeWithOppositeDepths) {
  std::mt19937 rng(4);
  const PinholeCamera camera = randomCamera(&rng);
  const PinholeCamera negated = camera.negated();
  EXPECT_FALSE(camera.improper());
  EXPECT_TRUE(negated.improper());
  EXPECT_LT((negated.projectionMatrix() + camera.projectionMatrix()).norm(), 1e-9);
  EXPECT_LT((negated.centre() - camera.centre()).norm(), 1e-9);
  const Eigen::Vector3d X =
      camera.centre() + 2.0 * camera.opticalAxis() + Eigen::Vector3d(0.1, 0, 0);
  EXPECT_NEAR(negated.depth(X), -camera.depth(X), 1e-9);
  EXPECT_LT((negated.project(X) - camera.project(X)).norm(), 1e-9);
  EXPECT_FALSE(negated.negated().improper());
}

TEST(Camera, RejectsBadParameters) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d singular = exampleK();
  singular(1, 1) = 0.0;
  EXPECT_THROW(PinholeCamera(singular, I, Eigen::Vector3d::Zero()), std::invalid_argument);
  Eigen::Matrix3d reflection = I;
  reflection(2, 2) = -1.0;
  EXPECT_THROW(PinholeCamera(exampleK(), reflection, Eigen::Vector3d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(PinholeCamera(exampleK(), 1.01 * I, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(exampleK(), I, Eigen::Vector3d(0, NAN, 0)), std::invalid_argument);
  EXPECT_THROW(PinholeCamera::fromProjection(Matrix34d::Zero()), std::invalid_argument);
}

TEST(FundamentalMatrix, EpipolarConstraintHoldsForRandomPoints) {
  std::mt19937 rng(5);
  for (int pair = 0; pair < 20; ++pair) {
    const PinholeCamera a = randomCamera(&rng), b = randomCamera(&rng);
    const Eigen::Matrix3d F = fundamentalMatrix(a, b);
    const Eigen::Matrix3d F_normalised = F / F.norm();
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d X = randomPoint(&rng);
      const Eigen::Vector3d x_a = a.project(X).homogeneous(), x_b = b.project(X).homogeneous();
      // Pixel coordinates reach ~1e3, so scale the residual by their norms to compare with 1e-9.
      EXPECT_LT(std::abs(x_b.dot(F_normalised * x_a)) / (x_a.norm() * x_b.norm()), 1e-9);
      EXPECT_LT(epipolarDistances(F, a.project(X), b.project(X)).max(), 1e-6);
    }
  }
}

TEST(FundamentalMatrix, DistanceMeasuresOffsetFromEpipolarLine) {
  std::mt19937 rng(9);
  const PinholeCamera a = randomCamera(&rng), b = randomCamera(&rng);
  const Eigen::Matrix3d F = fundamentalMatrix(a, b);
  const Eigen::Vector3d X = randomPoint(&rng);
  const Eigen::Vector2d x_a = a.project(X), x_b = b.project(X);
  const Eigen::Vector3d line = F * x_a.homogeneous();
  const Eigen::Vector2d unit_normal = line.head<2>().normalized();
  const EpipolarDistances d = epipolarDistances(F, x_a, x_b + 2.5 * unit_normal);
  EXPECT_NEAR(d.in_b_px, 2.5, 1e-6);
  EXPECT_GT(d.in_a_px, 0.0);
}

TEST(FundamentalMatrix, SkewIsCrossProduct) {
  const Eigen::Vector3d v(1.0, -2.0, 0.5), w(0.3, 0.7, -1.1);
  EXPECT_LT((skew(v) * w - v.cross(w)).norm(), 1e-15);
}

}  // namespace
}  // namespace sift_hull
