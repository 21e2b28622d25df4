// The two-view models of the voted LO-RANSAC filter: the minimal and least-squares solvers
// against exact projections, the residuals against their plain definitions, the RANSAC iteration
// count, and polishing a model against all the putatives.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <random>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/two_view_models.h"
#include "two_view_scene.h"

namespace sift_hull {
namespace {

using test::pairsOf;
using test::sceneMatches;
using test::twoCameras;
using test::TwoCameras;

Eigen::Matrix3d unit(const Eigen::Matrix3d& M) {
  const Eigen::Matrix3d U = M / M.norm();
  return U(2, 2) < 0 ? Eigen::Matrix3d(-U) : U;
}

// ---- two-view models ---------------------------------------------------------------------------

TEST(TwoViewModels, SevenPointsGiveTheExactFundamentalMatrix) {
  const LabelledMatches scene = sceneMatches(7, 0.0, 3, 0.0);
  PointPairs pairs;
  for (size_t m = 0; m < 7; ++m) {
    pairs.push(scene.putative.left(m).pt.x, scene.putative.left(m).pt.y,
               scene.putative.right(m).pt.x, scene.putative.right(m).pt.y);
  }
  const Eigen::Matrix3d Tl = hartleyNormalisation(pairs.left_x, pairs.left_y);
  const Eigen::Matrix3d Tr = hartleyNormalisation(pairs.right_x, pairs.right_y);
  Eigen::Matrix<double, 7, 2> l, r;
  for (int i = 0; i < 7; ++i) {
    l.row(i) = (Tl * Eigen::Vector3d(pairs.left_x[i], pairs.left_y[i], 1)).head<2>().transpose();
    r.row(i) = (Tr * Eigen::Vector3d(pairs.right_x[i], pairs.right_y[i], 1)).head<2>().transpose();
  }
  const std::vector<Eigen::Matrix3d> solutions = sevenPointFundamental(l, r);
  ASSERT_FALSE(solutions.empty());
  double nearest = INFINITY;
  for (const Eigen::Matrix3d& Fn : solutions) {
    const Eigen::Matrix3d F = unit(Tr.transpose() * Fn * Tl);
    nearest = std::min(nearest, (F - unit(twoCameras().F())).norm());
    EXPECT_NEAR(F.determinant(), 0.0, 1e-9);
    for (int i = 0; i < 7; ++i) {  // each solution passes through the seven points
      EXPECT_LT(modelResidual({false, F}, pairs.left_x[i], pairs.left_y[i], pairs.right_x[i],
                              pairs.right_y[i]),
                1e-6);
    }
  }
  EXPECT_LT(nearest, 1e-5);  // the true F is one of the (up to three) solutions (float input)
}

TEST(TwoViewModels, SevenPointsOfRankBelowSevenGiveNone) {
  // A repeated point or seven points on one line leave a null space of more than two
  // dimensions: no fundamental matrix is determined, so none is returned.
  const LabelledMatches scene = sceneMatches(7, 0.0, 3, 0.0);
  Eigen::Matrix<double, 7, 2> l, r;
  for (int i = 0; i < 7; ++i) {
    l.row(i) << scene.putative.left(i).pt.x / 320.0 - 1, scene.putative.left(i).pt.y / 240.0 - 1;
    r.row(i) << scene.putative.right(i).pt.x / 320.0 - 1,
        scene.putative.right(i).pt.y / 240.0 - 1;
  }
  ASSERT_FALSE(sevenPointFundamental(l, r).empty());
  Eigen::Matrix<double, 7, 2> repeated_l = l, repeated_r = r;
  repeated_l.row(6) = l.row(2), repeated_r.row(6) = r.row(2);
  EXPECT_TRUE(sevenPointFundamental(repeated_l, repeated_r).empty());
  Eigen::Matrix<double, 7, 2> line_l, line_r;
  for (int i = 0; i < 7; ++i) line_l.row(i) << 0.1 * i, 0.2, line_r.row(i) << 0.1 * i + 0.05, 0.2;
  EXPECT_TRUE(sevenPointFundamental(line_l, line_r).empty());
  Eigen::Matrix<double, 7, 2> nan_l = l;
  nan_l(3, 0) = NAN;
  EXPECT_TRUE(sevenPointFundamental(nan_l, r).empty());
}

TEST(TwoViewModels, FourPointsGiveTheHomographyAndCollinearOnesNone) {
  Eigen::Matrix3d H;
  H << 1.1, 0.2, 5, -0.1, 0.9, 7, 1e-4, 2e-4, 1;
  Eigen::Matrix<double, 4, 2> l, r;
  l << 0, 0, 1, 0, 0, 1, 1.3, 0.8;
  for (int i = 0; i < 4; ++i) r.row(i) = (H * l.row(i).transpose().homogeneous()).hnormalized();
  Eigen::Matrix3d found;
  ASSERT_TRUE(fourPointHomography(l, r, &found));
  EXPECT_LT((unit(found) - unit(H)).norm(), 1e-9);
  l.row(3) << 2, 0;  // three on the line y = 0
  EXPECT_FALSE(fourPointHomography(l, r, &found));
}

TEST(TwoViewModels, LeastSquaresRecoverNoiseFreeModels) {
  const LabelledMatches scene = sceneMatches(60, 0.0, 5, 0.0);
  Eigen::MatrixX2d l(60, 2), r(60, 2);
  for (int m = 0; m < 60; ++m) {
    l.row(m) << scene.putative.left(m).pt.x / 320.0 - 1, scene.putative.left(m).pt.y / 240.0 - 1;
    r.row(m) << scene.putative.right(m).pt.x / 320.0 - 1, scene.putative.right(m).pt.y / 240.0 - 1;
  }
  Eigen::Matrix3d F;
  ASSERT_TRUE(leastSquaresFundamental(l, r, Eigen::VectorXd::Ones(60), &F));
  for (int m = 0; m < 60; ++m) {
    EXPECT_NEAR(r.row(m).homogeneous().dot(F * l.row(m).transpose().homogeneous()), 0.0, 1e-5);
  }
  Eigen::Matrix3d H0, H;
  H0 << 0.9, -0.2, 0.1, 0.15, 1.05, -0.05, 0.02, -0.01, 1;
  for (int m = 0; m < 60; ++m) r.row(m) = (H0 * l.row(m).transpose().homogeneous()).hnormalized();
  ASSERT_TRUE(leastSquaresHomography(l, r, Eigen::VectorXd::Ones(60), &H));
  EXPECT_LT((unit(H) - unit(H0)).norm(), 1e-7);
  // Sizes that differ are refused.
  EXPECT_FALSE(leastSquaresFundamental(l, r.topRows(59), Eigen::VectorXd::Ones(60), &F));
  EXPECT_FALSE(leastSquaresHomography(l, r, Eigen::VectorXd::Ones(59), &H));
}

TEST(TwoViewModels, WeightedLeastSquaresEqualAPlainEigenvectorOfTheWeightedProduct) {
  // Noisy points and random weights, at sizes around the kernel's blocks of 8 and at 512 (whose
  // columns would lie 4 KiB apart unpadded): the smallest eigenvector of A^T W A computed plainly.
  for (int n : {8, 13, 61, 512}) {
    const LabelledMatches scene = sceneMatches(size_t(n), 0.0, 9, 0.5);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> weight(0.1, 1.0);
    Eigen::MatrixX2d l(n, 2), r(n, 2);
    Eigen::VectorXd w(n);
    Eigen::MatrixXd A(n, 9), B(2 * n, 9);
    Eigen::VectorXd wb(2 * n);
    for (int m = 0; m < n; ++m) {
      const double lx = scene.putative.left(m).pt.x / 320.0 - 1,
                   ly = scene.putative.left(m).pt.y / 240.0 - 1,
                   rx = scene.putative.right(m).pt.x / 320.0 - 1,
                   ry = scene.putative.right(m).pt.y / 240.0 - 1;
      l.row(m) << lx, ly;
      r.row(m) << rx, ry;
      w(m) = weight(random);
      A.row(m) << rx * lx, rx * ly, rx, ry * lx, ry * ly, ry, lx, ly, 1.0;
      B.row(2 * m) << -lx, -ly, -1, 0, 0, 0, rx * lx, rx * ly, rx;
      B.row(2 * m + 1) << 0, 0, 0, -lx, -ly, -1, ry * lx, ry * ly, ry;
      wb(2 * m) = wb(2 * m + 1) = w(m);
    }
    auto smallest = [](const Eigen::MatrixXd& M, const Eigen::VectorXd& weights) {
      const Eigen::MatrixXd normal = M.transpose() * weights.asDiagonal() * M;
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(normal);
      Eigen::Matrix3d X;
      for (int k = 0; k < 9; ++k) X(k / 3, k % 3) = solver.eigenvectors()(k, 0);
      return X;
    };
    Eigen::Matrix3d F, H;
    ASSERT_TRUE(leastSquaresFundamental(l, r, w, &F)) << n;
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(smallest(A, w),
                                          Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Vector3d s = svd.singularValues();
    s(2) = 0.0;
    const Eigen::Matrix3d F_plain = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
    EXPECT_LT((unit(F) - unit(F_plain)).norm(), 1e-8) << n;
    ASSERT_TRUE(leastSquaresHomography(l, r, w, &H)) << n;
    EXPECT_LT((unit(H) - unit(smallest(B, wb))).norm(), 1e-8) << n;
  }
}

TEST(TwoViewModels, ResidualsFollowTheirDefinitions) {
  const TwoCameras c = twoCameras();
  TwoViewModel f{false, c.F()}, h{true, Eigen::Matrix3d::Identity()};
  h.matrix << 1.2, 0.1, 4, -0.05, 0.95, -3, 1e-4, 0, 1;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(0, 640);
  PointPairs pairs;
  for (int i = 0; i < 200; ++i)
    pairs.push(float(u(random)), float(u(random)), float(u(random)), float(u(random)));
  std::vector<float> f2, h2;
  squaredResiduals(f, pairs, &f2);
  squaredResiduals(h, pairs, &h2);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector2d a(pairs.left_x[i], pairs.left_y[i]),
        b(pairs.right_x[i], pairs.right_y[i]);
    const double epipolar = epipolarDistances(c.F(), a, b).max();
    EXPECT_NEAR(modelResidual(f, a.x(), a.y(), b.x(), b.y()), epipolar, 1e-9 * (1 + epipolar));
    const double forward = ((h.matrix * a.homogeneous()).hnormalized() - b).norm();
    const double backward = ((h.matrix.inverse() * b.homogeneous()).hnormalized() - a).norm();
    const double transfer = std::max(forward, backward);
    EXPECT_NEAR(modelResidual(h, a.x(), a.y(), b.x(), b.y()), transfer, 1e-9 * (1 + transfer));
    EXPECT_NEAR(std::sqrt(f2[i]), epipolar, 1e-3 * (1 + epipolar));  // float
    EXPECT_NEAR(std::sqrt(h2[i]), transfer, 1e-3 * (1 + transfer));
  }
}

TEST(TwoViewModels, RansacIterationsFollowTheFormula) {
  EXPECT_EQ(ransacIterations(0.5, 7, 0.99, 100000), 588);  // log(0.01) / log(1 - 0.5^7)
  EXPECT_EQ(ransacIterations(0.9, 4, 0.99, 1000), 5);
  EXPECT_EQ(ransacIterations(1.0, 7, 0.99, 1000), 1);
  EXPECT_EQ(ransacIterations(0.0, 7, 0.99, 1000), 1000);
  EXPECT_EQ(ransacIterations(0.1, 7, 0.99, 1000), 1000);  // capped
}

/// The truncated quadratic of a model over the pairs (threshold 1 px) and its true inliers.
std::pair<double, size_t> costAndTrueInliers(const TwoViewModel& model, const PointPairs& pairs,
                                             const std::vector<MatchTruth>& truth) {
  std::vector<float> r2;
  squaredResiduals(model, pairs, &r2);
  double cost = 0.0;
  size_t found = 0;
  for (size_t i = 0; i < r2.size(); ++i) {
    cost += std::min(r2[i], 1.0f);
    found += r2[i] <= 1.0f && truth[i] == MatchTruth::kCorrect;
  }
  return {cost, found};
}

TEST(TwoViewModels, PolishingAnOffsetModelRecoversTheTrueMatches) {
  // The exact F of cameras turned 0.3 deg further: it loses many true matches at 1 px; refined
  // against all the putatives (60 % mismatches) it must lower the cost and keep about as many as
  // the exact F does.
  const LabelledMatches input = sceneMatches(600, 0.6, 5, 0.3);
  const PointPairs pairs = pairsOf(input.putative);
  TwoCameras offset = twoCameras();
  offset.R = Eigen::AngleAxisd(0.3 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * offset.R;
  TwoViewModel exact, start;
  exact.matrix = twoCameras().F(), start.matrix = offset.F();
  const auto [exact_cost, exact_found] = costAndTrueInliers(exact, pairs, input.truth);
  const auto [start_cost, start_found] = costAndTrueInliers(start, pairs, input.truth);
  const TwoViewModel polished = polishTwoViewModel(pairs, start, 1.0);
  const auto [cost, found] = costAndTrueInliers(polished, pairs, input.truth);
  std::cout << "true matches within 1 px: exact " << exact_found << ", offset " << start_found
            << ", polished " << found << "; cost " << exact_cost << ", " << start_cost << ", "
            << cost << "\n";
  ASSERT_LT(start_found, exact_found * 0.9);  // the offset is large enough to matter
  EXPECT_LT(cost, start_cost);
  EXPECT_GE(double(found), 0.98 * double(exact_found));
  EXPECT_FALSE(polished.homography);
}

TEST(TwoViewModels, PolishingLeavesWhatItCannotImprove) {
  const LabelledMatches input = sceneMatches(600, 0.3, 7, 0.3);
  const PointPairs pairs = pairsOf(input.putative);
  TwoViewModel broken;
  broken.matrix(0, 0) = NAN;
  EXPECT_TRUE(polishTwoViewModel(pairs, broken, 1.0).matrix.hasNaN());
  PointPairs few;
  for (size_t i = 0; i < 7; ++i) {
    few.push(pairs.left_x[i], pairs.left_y[i], pairs.right_x[i], pairs.right_y[i]);
  }
  TwoViewModel exact;
  exact.matrix = twoCameras().F();
  EXPECT_EQ(polishTwoViewModel(few, exact, 1.0).matrix, exact.matrix);
  // Never worse than where it started.
  const double before = costAndTrueInliers(exact, pairs, input.truth).first;
  EXPECT_LE(costAndTrueInliers(polishTwoViewModel(pairs, exact, 1.0), pairs, input.truth).first,
            before);
}

}  // namespace
}  // namespace sift_hull
