// Residuals in octave intervals (scaled_residuals.h): each image's residual divided by the
// sampling interval of its keypoint's SIFT octave.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "sift_hull/filters/scaled_residuals.h"
#include "sift_hull/geometry/camera.h"
#include "two_view_scene.h"

namespace sift_hull {
namespace {

TEST(ScaledResiduals, OctaveIntervalIsTheSizeOverTwiceTheBaseBlurAtLeastOne) {
  EXPECT_FLOAT_EQ(octaveInterval_px(3.2f), 1.0f);
  EXPECT_FLOAT_EQ(octaveInterval_px(12.8f), 4.0f);  // two octaves up
  EXPECT_FLOAT_EQ(octaveInterval_px(2.0f), 1.0f);   // the first octaves: a pixel
  EXPECT_FLOAT_EQ(octaveInterval_px(0.0f), 1.0f);   // no size (synthetic matches)
  EXPECT_FLOAT_EQ(octaveInterval_px(-5.0f), 1.0f);
  EXPECT_FLOAT_EQ(octaveInterval_px(std::nanf("")), 1.0f);
}

TEST(ScaledResiduals, EachImagesResidualIsMeasuredInItsOwnIntervals) {
  // A zoom by 3: a right keypoint 3 times larger, located 6 px off in the right image, is 2 px
  // off in the left one; in intervals (1 left, 3 right) both are 2.
  const TwoViewModel zoom{true, Eigen::Vector3d(3.0, 3.0, 1.0).asDiagonal()};
  EXPECT_NEAR(modelResidual(zoom, 10, 20, 36, 60), 6.0, 1e-9);
  EXPECT_NEAR(scaledModelResidual(zoom, 10, 20, 36, 60, 1.0, 3.0), 2.0, 1e-9);
  EXPECT_NEAR(scaledModelResidual(zoom, 10, 20, 36, 60, 1.0, 1.0), 6.0, 1e-9);
  // A fundamental matrix: each point's distance to its line over its own interval.
  const test::TwoCameras c = test::twoCameras();
  const TwoViewModel f{false, c.F()};
  const Eigen::Vector2d a(300, 200), b(310, 240);
  const EpipolarDistances d = epipolarDistances(c.F(), a, b);
  EXPECT_NEAR(scaledModelResidual(f, a.x(), a.y(), b.x(), b.y(), 2.0, 5.0),
              std::max(d.in_a_px / 2.0, d.in_b_px / 5.0), 1e-9 * (1 + d.max()));
}

TEST(ScaledResiduals, TheModelsLocalScaleIsItsJacobiansStretch) {
  // A similarity stretches by its scale everywhere; a homography by its Jacobian at the point.
  const TwoViewModel zoom{true, Eigen::Vector3d(2.5, 2.5, 1.0).asDiagonal()};
  EXPECT_NEAR(localScale(zoom, 100, 50), 2.5, 1e-12);
  TwoViewModel h{true, Eigen::Matrix3d::Identity()};
  h.matrix << 1.2, 0.1, 4, -0.05, 0.95, -3, 1e-3, 0, 1;
  const double x = 200, y = 100, step = 1e-4;
  const auto map = [&](double u, double v) -> Eigen::Vector2d {
    return (h.matrix * Eigen::Vector3d(u, v, 1.0)).hnormalized();
  };
  Eigen::Matrix2d J;
  J.col(0) = (map(x + step, y) - map(x - step, y)) / (2 * step);
  J.col(1) = (map(x, y + step) - map(x, y - step)) / (2 * step);
  EXPECT_NEAR(localScale(h, x, y), std::sqrt(std::abs(J.determinant())), 1e-6);
  EXPECT_DOUBLE_EQ(localScale(TwoViewModel{false, test::twoCameras().F()}, x, y), 1.0);
  // The allowances: the stretched side gets the scale, the other side 1 (and the reverse).
  PointPairs pairs;
  pairs.push(100, 50, 250, 125);
  const PairScales scales = modelScales(zoom, pairs);
  EXPECT_FLOAT_EQ(scales.right[0], 2.5f);
  EXPECT_FLOAT_EQ(scales.left[0], 1.0f);
  const PairScales shrunk =
      modelScales(TwoViewModel{true, Eigen::Vector3d(0.5, 0.5, 1.0).asDiagonal()}, pairs);
  EXPECT_FLOAT_EQ(shrunk.right[0], 1.0f);
  EXPECT_FLOAT_EQ(shrunk.left[0], 2.0f);
}

TEST(ScaledResiduals, TheFloatKernelAgreesWithTheDefinition) {
  const test::TwoCameras c = test::twoCameras();
  TwoViewModel f{false, c.F()}, h{true, Eigen::Matrix3d::Identity()};
  h.matrix << 1.2, 0.1, 4, -0.05, 0.95, -3, 1e-4, 0, 1;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(0, 640), s(1, 8);
  PointPairs pairs;
  PairScales scales;
  for (int i = 0; i < 200; ++i) {
    pairs.push(float(u(random)), float(u(random)), float(u(random)), float(u(random)));
    scales.push(float(s(random)), float(s(random)));
  }
  for (const TwoViewModel& model : {f, h}) {
    std::vector<float> r2;
    squaredScaledResiduals(model, pairs, scales, &r2);
    ASSERT_EQ(r2.size(), pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double r =
          scaledModelResidual(model, pairs.left_x[i], pairs.left_y[i], pairs.right_x[i],
                              pairs.right_y[i], scales.left[i], scales.right[i]);
      EXPECT_NEAR(std::sqrt(r2[i]), r, 1e-3 * (1 + r)) << "pair " << i;
    }
  }
  scales.left.pop_back();
  std::vector<float> r2;
  EXPECT_THROW(squaredScaledResiduals(f, pairs, scales, &r2), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
