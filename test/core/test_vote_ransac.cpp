// The voted LO-RANSAC filter (vote_ransac, today's best) and its two-view models: the minimal and
// least-squares solvers against exact projections, the residuals against their plain definitions,
// and the filter on synthetic putatives with known inliers (a 3D scene and a similarity, 30 % and
// 60 % outliers), rotation and zoom of the right image, two motions, pure noise, tiny and
// degenerate inputs. Its time is measured by `sift_hull bench-filters`, not here.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <random>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/two_view_models.h"
#include "sift_hull/filters/vote_ransac.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/synthetic/synthetic_matches.h"
#include "synthetic_putatives.h"

namespace sift_hull {
namespace {

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

TwoCameras twoCameras() {
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
LabelledMatches sceneMatches(size_t inliers, double outliers, unsigned seed, double noise_px) {
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

using test::differing;
using test::transformRight;
using test::twoMotions;

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

// ---- the filter --------------------------------------------------------------------------------

PointPairs pairsOf(const PutativeMatches& p) {
  PointPairs pairs;
  for (size_t m = 0; m < p.matches.size(); ++m) {
    pairs.push(p.left(m).pt.x, p.left(m).pt.y, p.right(m).pt.x, p.right(m).pt.y);
  }
  return pairs;
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

/// The share of the true matches that the exact F keeps at the filter's threshold: with 0.3 px of
/// noise on each coordinate some true matches lie beyond 1 px, so no filter can reach recall 1.
double oracleRecall(const LabelledMatches& input, double threshold_px) {
  TwoViewModel truth;
  truth.matrix = twoCameras().F();
  size_t correct = 0, within = 0;
  for (size_t m = 0; m < input.truth.size(); ++m) {
    if (input.truth[m] != MatchTruth::kCorrect) continue;
    const cv::Point2f &a = input.putative.left(m).pt, &b = input.putative.right(m).pt;
    ++correct;
    within += modelResidual(truth, a.x, a.y, b.x, b.y) <= threshold_px;
  }
  return double(within) / double(correct);
}

TEST(VoteRansac, SeparatesASceneAtThirtyAndSixtyPercentOutliers) {
  // Ten scenes each: the recall is measured against what the exact F keeps (the oracle), since
  // the found F differs from it by the noise of the fit (on 100 scenes at 60 % outliers the
  // largest shortfall was 0.042, the mean 0.004).
  const FilterConfigs configs;
  const auto filter = makeFilter("vote_ransac", configs);
  for (double outliers : {0.3, 0.6}) {
    double shortfall_sum = 0.0;
    const unsigned first = 41, count = 10;
    for (unsigned seed = first; seed < first + count; ++seed) {
      const LabelledMatches input = sceneMatches(600, outliers, seed, 0.3);
      const FilterScores s = scoreFilter(input.truth, filter->apply(input.putative));
      const double oracle = oracleRecall(input, configs.magsac.max_epipolar_px);
      std::cout << "scene " << seed << ", " << outliers << " outliers: P " << s.precision() << " R "
                << s.recall() << " (exact F: " << oracle << ")\n";
      EXPECT_GE(s.recall(), oracle - 0.07) << outliers << " seed " << seed;
      EXPECT_GE(s.precision(), 0.97) << outliers << " seed " << seed;
      shortfall_sum += oracle - s.recall();
    }
    EXPECT_LE(shortfall_sum / count, 0.015) << outliers;
  }
}

TEST(VoteRansac, ASimilarityPairIsFittedByTheHomography) {
  for (double outliers : {0.3, 0.6}) {
    const LabelledMatches input = test::synthetic(outliers, 23);
    const FilterConfigs configs;
    const std::vector<TwoViewModel> motions =
        voteRansacMotions(input.putative, {configs.vote_ransac, configs.guided, configs.magsac});
    ASSERT_EQ(motions.size(), 1u) << outliers;
    EXPECT_TRUE(motions[0].homography);
    const FilterScores s =
        scoreFilter(input.truth, makeFilter("vote_ransac", configs)->apply(input.putative));
    EXPECT_GE(s.recall(), 0.97) << outliers;
    EXPECT_GE(s.precision(), 0.97) << outliers;
  }
}

TEST(VoteRansac, KeepsWhatThePlainReferenceKeepsUnderItsMotions) {
  const LabelledMatches input = sceneMatches(500, 0.4, 43, 0.3);
  const FilterConfigs c;
  const std::vector<TwoViewModel> motions =
      voteRansacMotions(input.putative, {c.vote_ransac, c.guided, c.magsac});
  const FilterResult result = makeFilter("vote_ransac", c)->apply(input.putative);
  ASSERT_FALSE(motions.empty());
  size_t borderline = 0;
  for (size_t m = 0; m < input.truth.size(); ++m) {
    const cv::Point2f &a = input.putative.left(m).pt, &b = input.putative.right(m).pt;
    bool keep = false;
    double nearest_edge = INFINITY;
    for (const TwoViewModel& motion : motions) {
      const double limit =
          motion.homography ? c.guided.guided_max_transfer_px : c.magsac.max_epipolar_px;
      const double r = modelResidual(motion, a.x, a.y, b.x, b.y);
      keep = keep || r <= limit;
      nearest_edge = std::min(nearest_edge, std::abs(r - limit));
    }
    if (bool(result.keep[m]) != keep) {
      ++borderline;
      EXPECT_LT(nearest_edge, 1e-3) << "match " << m << " differs away from its threshold";
    }
  }
  EXPECT_LE(borderline, 1u);  // float against double residuals, at the threshold only
}

TEST(VoteRansac, SameDecisionsAfterRotatingTheRightImage) {
  // The votes are found from the data, so a rotation moves nothing the residuals see.
  const LabelledMatches input = sceneMatches(600, 0.3, 47, 0.3);
  const auto filter = makeFilter("best", FilterConfigs());
  const FilterResult before = filter->apply(input.putative);
  for (double deg : {90.0, 37.0, -120.0}) {
    const FilterResult after = filter->apply(transformRight(input.putative, deg, 1.0));
    std::cout << "best rotated " << deg << ": " << differing(before, after) << " of "
              << input.truth.size() << " differ\n";
    EXPECT_LE(differing(before, after), input.truth.size() / 100) << deg;  // measured: 0
  }
}

TEST(VoteRansac, SameDecisionsAfterZoomingTheRightImageWhereNoiseAllows) {
  // The thresholds are pixels, so a zoom scales the right image's noise against them (0.3 px
  // noise zoomed 1.6x drops 11 % of the inliers at 1 px, as it would for MAGSAC): with exact
  // inliers, zooming and turning must change no decision but the rare outlier at the edge.
  const LabelledMatches input = sceneMatches(600, 0.3, 71, 0.0);
  const auto filter = makeFilter("best", FilterConfigs());
  const FilterResult before = filter->apply(input.putative);
  EXPECT_GE(scoreFilter(input.truth, before).recall(), 0.99);
  for (const auto& [deg, scale] : {std::pair{25.0, 1.6}, {-70.0, 0.5}, {0.0, 2.5}}) {
    const FilterResult after = filter->apply(transformRight(input.putative, deg, scale));
    std::cout << "best rotated " << deg << " zoomed " << scale << ": " << differing(before, after)
              << " of " << input.truth.size() << " differ\n";
    EXPECT_LE(differing(before, after), input.truth.size() / 100) << deg << " " << scale;
  }
}

TEST(VoteRansac, FindsBothMotionsWhereOneModelFails) {
  const LabelledMatches input = twoMotions();
  const FilterScores s =
      scoreFilter(input.truth, makeFilter("vote_ransac", FilterConfigs())->apply(input.putative));
  std::cout << "two motions: R " << s.recall() << " P " << s.precision() << "\n";
  EXPECT_GE(s.recall(), 0.95);
  EXPECT_GE(s.precision(), 0.97);
}

TEST(VoteRansac, TwoMotionsCloseTogetherKeepTheirOwnMatches) {
  // Two similarities over the same image (20 and 24 deg, 1.2x), the second shifted 8 px to the
  // right: the matches of each lie within three times the other's 3 px threshold over much of
  // the image, where each motion's refinement against all matches looks. Both motions must be
  // found and keep their matches (a translation alone would not do: H and a shifted H share one
  // fundamental matrix, which then explains both).
  LabelledMatches a = test::synthetic(0.0, 13), b = test::synthetic(0.0, 17, 24.0, 1.2);
  const int offset = static_cast<int>(a.putative.left_keypoints.size());
  for (size_t m = 0; m < b.putative.matches.size(); ++m) {
    a.putative.left_keypoints.push_back(b.putative.left(m));
    a.putative.right_keypoints.push_back(b.putative.right(m));
    a.putative.right_keypoints.back().pt.x += 8.f;
    a.putative.matches.emplace_back(offset + int(m), offset + int(m), 0.f);
    a.truth.push_back(b.truth[m]);
  }
  injectMismatches(&a, 0.3, 19);
  const FilterConfigs configs;
  const std::vector<TwoViewModel> motions =
      voteRansacMotions(a.putative, {configs.vote_ransac, configs.guided, configs.magsac});
  ASSERT_EQ(motions.size(), 2u);
  const FilterResult result = makeFilter("vote_ransac", configs)->apply(a.putative);
  for (int object = 0; object < 2; ++object) {
    size_t correct = 0, kept = 0;
    for (size_t m = 0; m < a.truth.size(); ++m) {
      const bool mine =
          object == 0 ? m < size_t(offset) : (m >= size_t(offset) && m < 2 * size_t(offset));
      if (!mine || a.truth[m] != MatchTruth::kCorrect) continue;
      ++correct;
      kept += result.keep[m];
    }
    std::cout << "object " << object << ": " << kept << " of " << correct << " kept\n";
    EXPECT_GE(double(kept), 0.95 * double(correct)) << object;
  }
  EXPECT_GE(scoreFilter(a.truth, result).precision(), 0.97);
}

TEST(VoteRansac, PureNoiseKeepsAlmostNothing) {
  LabelledMatches input = test::synthetic(0.0, 53);
  input.putative.matches.resize(1), input.truth.resize(1);
  injectMismatches(&input, 0.998, 59);  // about 500 random pairs
  const FilterResult result = makeFilter("vote_ransac", FilterConfigs())->apply(input.putative);
  EXPECT_LE(result.keptCount(), input.truth.size() / 50);
}

TEST(VoteRansac, BestIsVoteRansacAndSeedsRepeat) {
  const LabelledMatches input = sceneMatches(400, 0.3, 61, 0.3);
  FilterConfigs configs;
  configs.magsac.seed = 4;
  const FilterResult a = makeFilter("best", configs)->apply(input.putative);
  EXPECT_EQ(makeFilter("vote_ransac", configs)->apply(input.putative).keep, a.keep);
  EXPECT_EQ(makeFilter("best", configs)->apply(input.putative).keep, a.keep);
}

TEST(VoteRansac, TinyAndDegenerateInputsKeepNothingWithoutThrowing) {
  const auto filter = makeFilter("vote_ransac", FilterConfigs());
  for (size_t n : {0u, 1u, 7u, 19u}) {
    LabelledMatches input = test::synthetic(0.0, 37);
    input.putative.matches.resize(std::min(n, input.putative.matches.size()));
    EXPECT_EQ(filter->apply(input.putative).keptCount(), 0u) << n << " matches";
  }
  PutativeMatches same;  // every match at one point: no motion can be fitted
  for (int i = 0; i < 50; ++i) {
    same.left_keypoints.emplace_back(cv::Point2f(5, 5), 4.f, 0.f);
    same.right_keypoints.emplace_back(cv::Point2f(9, 9), 4.f, 0.f);
    same.matches.emplace_back(i, i, 0.f);
  }
  EXPECT_NO_THROW(filter->apply(same));
  LabelledMatches odd = sceneMatches(200, 0.3, 67, 0.3);
  for (size_t k = 0; k < odd.putative.left_keypoints.size(); k += 3) {
    odd.putative.left_keypoints[k].angle = -1.f;  // no orientation: no vote
    odd.putative.right_keypoints[k].size = 0.f;
  }
  odd.putative.left_keypoints[1].pt.x = NAN;
  odd.putative.right_keypoints[2].pt.y = 1e30f;
  const FilterResult result = filter->apply(odd.putative);
  EXPECT_FALSE(result.keep[1]);
  EXPECT_TRUE(std::isnan(result.score[1]));
  EXPECT_GE(scoreFilter(odd.truth, result).recall(), 0.95);
}

TEST(VoteRansac, RejectsInvalidConfigs) {
  std::vector<FilterConfigs> bad(6);
  bad[0].vote_ransac.vote_ransac_max_angle_deg = 0.0;
  bad[1].vote_ransac.vote_ransac_max_angle_deg = 181.0;
  bad[2].vote_ransac.vote_ransac_max_scale_ratio = 1.0;
  bad[3].vote_ransac.vote_ransac_max_scale_ratio = INFINITY;
  bad[4].vote_ransac.vote_ransac_max_fit_points = 15;
  bad[5].vote_ransac.vote_ransac_max_angle_deg = NAN;
  for (const FilterConfigs& configs : bad) EXPECT_THROW(validate(configs), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
