// Distance maps sampled below full resolution (reducedSignedDistanceMap) against the
// full-resolution transform, the run-length masks the views keep, and the hull built from
// reduced maps against the full-resolution one on a high-resolution synthetic scene.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <random>

#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/distance_map.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/hull/run_length_mask.h"
#include "sift_hull/synthetic/mask_render.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// An ellipse with a hole, a one-pixel line sticking out, a thin diagonal bar and a separate
/// small square: smooth contours, corners and structures thinner than a block.
cv::Mat testMask() {
  cv::Mat mask = cv::Mat::zeros(900, 1200, CV_8UC1);
  cv::ellipse(mask, cv::Point(520, 430), cv::Size(300, 210), 20.0, 0.0, 360.0, 255, cv::FILLED);
  cv::circle(mask, cv::Point(560, 420), 40, 0, cv::FILLED);
  cv::line(mask, cv::Point(800, 430), cv::Point(1000, 470), 255, 1);
  cv::line(mask, cv::Point(300, 700), cv::Point(480, 820), 255, 3);
  cv::rectangle(mask, cv::Rect(1050, 100, 9, 7), 255, cv::FILLED);
  return mask;
}

/// Over points spread over the full map's window (a pixel inside its edges): the largest
/// |reduced - full| where the full map is within `band_px` of the contour, and the largest
/// excess sign(reduced) (reduced - full), which the stated bound must cover.
struct Differences {
  double near_contour = 0.0, excess = 0.0, mean_near_contour = 0.0;
};

Differences compare(const SignedDistanceMap& full, const SignedDistanceMap& reduced,
                    double band_px) {
  const cv::Point origin = full.origin();
  const cv::Size size = full.map().size();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(origin.x + 1, origin.x + size.width - 2);
  std::uniform_real_distribution<double> v(origin.y + 1, origin.y + size.height - 2);
  Differences result;
  int near = 0;
  for (int i = 0; i < 200000; ++i) {
    const double u_px = u(random), v_px = v(random);
    const double exact = full.at(u_px, v_px), value = reduced.at(u_px, v_px);
    if (std::abs(exact) <= band_px) {
      result.near_contour = std::max(result.near_contour, std::abs(value - exact));
      result.mean_near_contour += std::abs(value - exact);
      ++near;
    }
    const double sign = value > 0.0 ? 1.0 : (value < 0.0 ? -1.0 : 0.0);
    result.excess = std::max(result.excess, sign * (value - exact));
  }
  result.mean_near_contour /= std::max(near, 1);
  return result;
}

TEST(RunLengthMask, DecodesToTheMaskAndAnswersPixelQueries) {
  const cv::Mat mask = testMask();
  const RunLengthMask encoded(mask);
  EXPECT_EQ(cv::countNonZero(encoded.decode() != mask), 0);
  EXPECT_EQ(encoded.insideCount(), static_cast<size_t>(cv::countNonZero(mask)));
  EXPECT_EQ(encoded.insideBounds(), cv::boundingRect(mask));
  EXPECT_LT(encoded.memoryBytes(), mask.total() / 20);
  for (int v = 0; v < mask.rows; v += 7) {
    for (int u = 0; u < mask.cols; u += 3) {
      ASSERT_EQ(encoded.at(u, v), mask.at<uint8_t>(v, u) != 0) << u << ", " << v;
    }
  }
  EXPECT_FALSE(encoded.at(-1, 0));
  EXPECT_FALSE(encoded.at(0, mask.rows));
  const SilhouetteBounds a = silhouetteBounds(mask, false), b = silhouetteBounds(encoded, false);
  EXPECT_EQ(a.u_min_px, b.u_min_px);
  EXPECT_EQ(a.v_max_px, b.v_max_px);
  EXPECT_EQ(a.has_u_max, b.has_u_max);
}

class ReducedMap : public ::testing::TestWithParam<int> {};

TEST_P(ReducedMap, EqualsTheFullResolutionMapWithinItsBoundAndExactlyAtSamplesNearTheContour) {
  const int reduction = GetParam();
  const cv::Mat mask = testMask();
  const SilhouetteBounds bounds = silhouetteBounds(mask, false);
  const SignedDistanceMap full(mask, bounds, 16);
  const SignedDistanceMap reduced =
      reducedSignedDistanceMap(RunLengthMask(mask), bounds, 16, reduction);
  ASSERT_EQ(reduced.reduction(), reduction);
  EXPECT_LE(reduced.errorBound_px(), reducedDistanceErrorBound_px(reduction));
  EXPECT_LT(reduced.errorBound_px(), 0.75 * reduction);  // measured, well below the a-priori one
  EXPECT_GT(reduced.errorBound_px(), 0.0f);
  const Differences differences = compare(full, reduced, reduction);
  EXPECT_LE(differences.near_contour, reducedDistanceErrorBound_px(reduction));
  EXPECT_LT(differences.mean_near_contour, 0.05 * reduction);
  EXPECT_LE(differences.excess, reduced.errorBound_px());
  std::cout << "reduction " << reduction << ": stated bound " << reduced.errorBound_px()
            << " px; near the contour max |difference| " << differences.near_contour << " mean "
            << differences.mean_near_contour << " px; largest excess " << differences.excess
            << " px\n";
  // At the samples within a block of the contour, the full map's value itself.
  const double first = 0.5 * (reduction - 1);
  for (int row = 0; row < reduced.map().rows - 1; ++row) {
    for (int col = 0; col < reduced.map().cols - 1; ++col) {
      const double u = reduced.origin().x + col * reduction + first;
      const double v = reduced.origin().y + row * reduction + first;
      if (std::abs(full.at(u, v)) > reduction) continue;
      ASSERT_NEAR(reduced.at(u, v), full.at(u, v), 1e-3) << "sample " << col << ", " << row;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Factors, ReducedMap, ::testing::Values(2, 3, 4, 8));

TEST(ReducedMap, OneIsTheFullResolutionMap) {
  const cv::Mat mask = testMask();
  const SilhouetteBounds bounds = silhouetteBounds(mask, false);
  const SignedDistanceMap full(mask, bounds, 16);
  const SignedDistanceMap same = reducedSignedDistanceMap(RunLengthMask(mask), bounds, 16, 1);
  EXPECT_EQ(cv::countNonZero(same.map() != full.map()), 0);
  EXPECT_EQ(same.origin(), full.origin());
  EXPECT_EQ(same.errorBound_px(), 0.0f);
}

/// 8 views of 2000x1500 of the default sculpture, masks only.
HullInput highResolutionScene() {
  SceneConfig config;
  config.views = 8;
  config.layout = "sphere";
  config.width_px = 2000;
  config.height_px = 1500;
  const Shape shape = Shape::byName(config.shape);
  HullInput input;
  for (const CalibratedView& view : sceneCameras(config, shape)) {
    input.names.push_back(view.name);
    input.cameras.push_back(view.camera);
    input.run_length_masks.emplace_back(
        renderMask(shape, view.camera, cv::Size(config.width_px, config.height_px)));
  }
  return input;
}

TEST(ReducedMap, HullReprojectsAsTheFullResolutionHullDoes) {
  const HullInput input = highResolutionScene();
  HullConfig config;
  config.max_depth = 7;
  const HullResult reduced = buildHull(input, config);
  config.distance_reduction = 1;
  const HullResult full = buildHull(input, config);
  int largest = 1;
  for (const HullView& view : reduced.hull.views()) {
    largest = std::max(largest, view.distanceReduction());
  }
  EXPECT_GE(largest, 4);  // the case under test is reduced
  for (const HullView& view : full.hull.views()) EXPECT_EQ(view.distanceReduction(), 1);
  const ReprojectionIoU reduced_iou = reprojectionIoU(reduced.mesh, reduced.hull.views());
  const ReprojectionIoU full_iou = reprojectionIoU(full.mesh, full.hull.views());
  EXPECT_GT(full_iou.mean, 0.95);
  EXPECT_NEAR(reduced_iou.mean, full_iou.mean, 0.002);
  EXPECT_TRUE(reduced.mesh_check.watertight);
}

TEST(ReducedMap, ReductionFollowsTheVoxelsProjectedSize) {
  const HullInput input = highResolutionScene();
  Box3d box;
  box.min_W = Eigen::Vector3d::Constant(-1.0);
  box.max_W = Eigen::Vector3d::Constant(1.0);
  HullConfig config;
  config.max_depth = 7;
  const cv::Size size = input.run_length_masks[0].size();
  const int at_depth_7 = distanceReduction(input.cameras[0], size, box, config);
  EXPECT_GE(at_depth_7, 2);
  config.max_depth = 9;
  const int at_depth_9 = distanceReduction(input.cameras[0], size, box, config);
  EXPECT_LT(at_depth_9, at_depth_7);  // a quarter of the voxel edge
  EXPECT_EQ(distanceReduction(input.cameras[0], cv::Size(640, 480), box, config), 1);
  config.distance_reduction = 5;
  EXPECT_EQ(distanceReduction(input.cameras[0], cv::Size(640, 480), box, config), 5);
  Box3d behind = box;  // a box reaching behind the camera
  behind.min_W = input.cameras[0].centre() - Eigen::Vector3d::Constant(0.1);
  config.distance_reduction = 0;
  EXPECT_EQ(distanceReduction(input.cameras[0], size, behind, config), 1);
}

/// How many points of a grid in the ball of radius `radius` around `centre` the view keeps, of
/// `total`.
int keptShare(const HullView& view, const Eigen::Vector3d& centre, double radius, int* total) {
  int kept = 0;
  *total = 0;
  const int steps = 6;
  for (int i = -steps; i <= steps; ++i) {
    for (int j = -steps; j <= steps; ++j) {
      for (int k = -steps; k <= steps; ++k) {
        const Eigen::Vector3d offset = Eigen::Vector3d(i, j, k) * (radius / steps);
        if (offset.norm() > radius) continue;
        ++*total;
        kept += view.keeps(centre + offset);
      }
    }
  }
  return kept;
}

TEST(ReducedMap, BallVerdictsStayConservative) {
  const HullInput input = highResolutionScene();
  const HullView view(input.names[0], input.cameras[0], input.run_length_masks[0], HullConfig(), 8);
  ASSERT_EQ(view.distanceReduction(), 8);
  std::mt19937 random(3);
  std::uniform_real_distribution<float> coordinate(-1.2f, 1.2f);
  int outside = 0, inside = 0;
  for (int batch = 0; batch < 200; ++batch) {
    float x[32], y[32], z[32], values[32];
    for (int i = 0; i < 32; ++i) {
      x[i] = coordinate(random), y[i] = coordinate(random), z[i] = coordinate(random);
      values[i] = -1e9f;
    }
    const float radius = 0.005f * (1 + batch % 8);
    uint32_t out_bits = 0, in_bits = 0;
    view.classifyBalls({x, y, z, 32}, radius, values, &out_bits, &in_bits);
    for (int i = 0; i < 32; ++i) {
      int total = 0;
      const int kept = keptShare(view, Eigen::Vector3d(x[i], y[i], z[i]), radius, &total);
      if ((out_bits >> i) & 1) {
        ++outside;
        ASSERT_EQ(kept, 0) << "ball " << batch << "/" << i;
      }
      if ((in_bits >> i) & 1) {
        ++inside;
        ASSERT_EQ(kept, total) << "ball " << batch << "/" << i;
      }
    }
  }
  EXPECT_GT(outside, 100);  // the verdicts are not vacuous
  EXPECT_GT(inside, 100);
}

}  // namespace
}  // namespace sift_hull
