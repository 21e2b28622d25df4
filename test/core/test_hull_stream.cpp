// HullStream, the hull node's worker: views wait until they bound a box, then refine the hull;
// views named in skip_views and views seen from where a view already taken was are left out.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::ring;
using test::streamConfig;

/// The camera moved by `offset_m` along world x and turned by `angle_deg` about its own y axis.
PinholeCamera moved(const PinholeCamera& camera, double offset_m, double angle_deg) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(angle_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return PinholeCamera::fromCentre(camera.K(), turn * camera.R(),
                                   camera.centre() + Eigen::Vector3d(offset_m, 0, 0));
}

TEST(HullStream, WaitsForABoxThenRefinesWithEveryView) {
  const HullInput input = ring(8);
  HullStream stream(streamConfig(6));
  EXPECT_EQ(stream.add(input.names[0], input.cameras[0], input.masks[0]),
            HullStream::Outcome::kWaiting);
  EXPECT_FALSE(stream.hasHull());
  EXPECT_FALSE(stream.whyNoBox().empty());
  double previous_volume = 0.0;
  for (size_t i = 1; i < input.masks.size(); ++i) {
    EXPECT_EQ(stream.add(input.names[i], input.cameras[i], input.masks[i]),
              HullStream::Outcome::kCarved)
        << input.names[i];
    const double volume = stream.hull().stats().occupied_volume_m3;
    if (i > 1) {
      EXPECT_LE(volume, previous_volume * (1.0 + 1e-9)) << "a view only carves";
    }
    previous_volume = volume;
  }
  EXPECT_EQ(stream.waitingViews(), 0u);
  EXPECT_EQ(stream.redundantViews(), 0u);
}

TEST(HullStream, LeavesOutViewsSeenFromWhereAViewAlreadyTakenWas) {
  const HullInput input = ring(8);
  HullStream stream(streamConfig(5));  // 1 cm and 1 degree
  for (size_t i = 0; i < 3; ++i) stream.add(input.names[i], input.cameras[i], input.masks[i]);
  ASSERT_TRUE(stream.hasHull());
  const size_t nodes = stream.hull().stats().nodes;
  const PinholeCamera& camera = input.cameras[0];
  using Outcome = HullStream::Outcome;
  EXPECT_EQ(stream.add("again", camera, input.masks[0]), Outcome::kRedundant);
  EXPECT_EQ(stream.add("5 mm", moved(camera, 0.005, 0.0), input.masks[0]), Outcome::kRedundant);
  EXPECT_EQ(stream.add("0.5 deg", moved(camera, 0.0, 0.5), input.masks[0]), Outcome::kRedundant);
  EXPECT_EQ(stream.redundantViews(), 3u);
  EXPECT_EQ(stream.hull().stats().nodes, nodes);
  EXPECT_EQ(stream.add("5 cm", moved(camera, 0.05, 0.0), input.masks[0]), Outcome::kCarved);
  EXPECT_EQ(stream.add("2 deg", moved(camera, 0.0, 2.0), input.masks[0]), Outcome::kCarved);
  stream.reset();
  EXPECT_EQ(stream.redundantViews(), 0u);
  EXPECT_EQ(stream.add("after reset", camera, input.masks[0]), Outcome::kWaiting);
}

/// The ring scaled `factor` times: intrinsics and masks (nearest neighbour).
HullInput scaled(HullInput input, double factor) {
  for (size_t i = 0; i < input.masks.size(); ++i) {
    Eigen::Matrix3d K = input.cameras[i].K();
    K.topRows<2>() *= factor;
    input.cameras[i] =
        PinholeCamera::fromCentre(K, input.cameras[i].R(), input.cameras[i].centre());
    cv::resize(input.masks[i], input.masks[i], cv::Size(), factor, factor, cv::INTER_NEAREST);
  }
  return input;
}

TEST(HullStream, SamplesTheMapsOfLargeViewsAtTheReductionTheBoxAllows) {
  const HullInput input = scaled(ring(6), 8.0);  // 2560x1920
  HullStreamConfig config = streamConfig(6);
  HullStream reduced(config);
  config.hull.distance_reduction = 1;
  HullStream full(config);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    reduced.add(input.names[i], input.cameras[i], input.masks[i]);
    full.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(reduced.hasHull());
  const std::vector<HullView>& views = reduced.hull().views();
  ASSERT_EQ(views.size(), input.masks.size());
  EXPECT_EQ(views.front().distanceReduction(), 1) << "it waited for the box";
  EXPECT_GT(views.back().distanceReduction(), 1);
  for (const HullView& view : full.hull().views()) EXPECT_EQ(view.distanceReduction(), 1);
  const double volume = reduced.hull().stats().occupied_volume_m3;
  const double reference = full.hull().stats().occupied_volume_m3;
  EXPECT_NEAR(volume, reference, 0.005 * reference);  // measured: 0.03 % apart
}

/// The largest distance between corresponding faces of two boxes.
double faceDistance(const Box3d& a, const Box3d& b) {
  return std::max((a.min_W - b.min_W).cwiseAbs().maxCoeff(),
                  (a.max_W - b.max_W).cwiseAbs().maxCoeff());
}

TEST(HullStream, RefitsItsBoxAsViewsShrinkItToTheOfflineHullsBoxAndResolution) {
  const HullInput input = test::sceneHullInput("sculpture", 12, "ring");
  HullStreamConfig config = streamConfig(6);
  HullStream stream(config);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  EXPECT_GT(stream.refits(), 0u) << "the first views' box is larger than all views' box";
  const HullResult offline = buildHull(input, config.hull);
  const HullCube& cube = stream.hull().cube();
  const HullCube& expected = offline.hull.cube();
  EXPECT_EQ(cube.depth, expected.depth);
  EXPECT_NEAR(cube.resolution_m, expected.resolution_m, 0.02 * expected.resolution_m);
  EXPECT_LE(faceDistance(stream.box(), offline.box), expected.resolution_m);
  EXPECT_LE(faceDistance(cube.box(), expected.box()), 2 * expected.resolution_m);
  const double volume = stream.hull().stats().occupied_volume_m3;
  EXPECT_NEAR(volume, offline.hull.stats().occupied_volume_m3,
              0.05 * offline.hull.stats().occupied_volume_m3);
  stream.reset();
  EXPECT_EQ(stream.refits(), 0u);
}

TEST(HullStream, KeepsAGivenBoxAndTakesAResolutionInMetres) {
  const HullInput input = test::sceneHullInput("sculpture", 12, "ring");
  HullStreamConfig config = streamConfig(6);
  const Box3d box = buildHull(input, config.hull).box;
  Box3d larger = box;
  larger.min_W -= Eigen::Vector3d::Constant(0.5);
  larger.max_W += Eigen::Vector3d::Constant(0.5);
  config.box = larger;
  config.hull.resolution_m = 0.05;
  HullStream stream(config);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  EXPECT_EQ(stream.refits(), 0u);
  EXPECT_EQ(faceDistance(stream.box(), larger), 0.0);
  EXPECT_EQ(stream.hull().cube().resolution_m, 0.05) << "octomap_server's resolution, exactly";
  const double longest_m = larger.size().maxCoeff();
  const int depth = stream.hull().cube().depth;
  EXPECT_GE(0.05 * ((1 << depth) - 3), longest_m) << "the cube covers the box";
  EXPECT_LT(0.05 * ((1 << (depth - 1)) - 3), longest_m) << "the least such depth";
}

TEST(HullStream, TakesEveryViewWithNoMinimumSeparation) {
  const HullInput input = ring(4);
  HullStreamConfig config = streamConfig(5);
  config.min_view_distance_m = 0.0;
  config.min_view_angle_deg = 0.0;
  HullStream stream(config);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  EXPECT_EQ(stream.add("again", input.cameras[0], input.masks[0]), HullStream::Outcome::kCarved);
}

TEST(HullStream, SkipsNamedViewsAndRefusesBadSettings) {
  const HullInput input = ring(2);
  HullStreamConfig config = streamConfig(5);
  config.skip_views = {input.names[1]};
  HullStream stream(config);
  EXPECT_EQ(stream.add(input.names[1], input.cameras[1], input.masks[1]),
            HullStream::Outcome::kSkipped);
  EXPECT_EQ(stream.waitingViews(), 0u);
  config.min_view_distance_m = -1.0;
  EXPECT_THROW(HullStream{config}, std::invalid_argument);
  config.min_view_distance_m = 0.01;
  config.min_view_angle_deg = std::nan("");
  EXPECT_THROW(HullStream{config}, std::invalid_argument);
  config.min_view_angle_deg = 200.0;
  EXPECT_THROW(HullStream{config}, std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
