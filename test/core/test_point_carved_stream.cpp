// PointCarvedStream: a streamed hull that surface points arriving pair by pair carve, checked
// against the renderer's ground truth (the concave scenes' true solids).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "concave_scene.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/refine/point_carved_stream.h"

namespace sift_hull {
namespace {

/// View v's exact points as a "pair" of that view's camera with itself.
std::vector<SurfacePoint> pointsOfView(const std::vector<RenderedView>& views, uint32_t v) {
  std::vector<SurfacePoint> points;
  for (const SurfacePoint& point : depthMapPoints(views, 4)) {
    if (point.views.front() == v) points.push_back(point);
  }
  return points;
}

HullStreamConfig streamConfig(int max_depth) {
  HullStreamConfig config;
  config.hull.max_depth = max_depth;
  return config;
}

struct CupStream : ::testing::Test {
  CupStream() : scene("cup", 7) {}

  void addView(PointCarvedStream* stream, size_t v) {
    const RenderedView& view = scene.views[v];
    stream->add("view_" + std::to_string(v), view.view.camera, view.mask);
  }
  void addPoints(PointCarvedStream* stream, uint32_t v) {
    const PinholeCamera& camera = scene.views[v].view.camera;
    stream->addSurfacePoints(camera, camera, pointsOfView(scene.views, v), v);
  }
  SolidSamples samples(const VisualHull& hull) const {
    const Shape filled = scene.shape.withoutCuts();
    return sampleAgainstSolid(
        hull, [&](const Eigen::Vector3d& X) { return scene.shape.contains(X); }, 96,
        [&](const Eigen::Vector3d& X) { return filled.contains(X) && !scene.shape.contains(X); });
  }

  ConcaveScene scene;
};

TEST_F(CupStream, PointsWaitForTheBoxThenCarveTheCavityAndNothingOfTheSolid) {
  PointCarvedStream stream(streamConfig(7), {});
  for (uint32_t v = 0; v < scene.views.size(); ++v) addPoints(&stream, v);
  EXPECT_FALSE(stream.refineDue()) << "no hull yet: the points must wait";
  for (size_t v = 0; v < scene.views.size(); ++v) addView(&stream, v);
  ASSERT_TRUE(stream.stream().hasHull());
  ASSERT_TRUE(stream.refineDue());
  const SolidSamples before = samples(stream.stream().hull());
  const PointCarvedStream::Refinement refinement = stream.refine();
  EXPECT_FALSE(stream.refineDue()) << "nothing new since";
  EXPECT_GT(refinement.free_voxels, 0u);
  EXPECT_EQ(refinement.newest_stamp_ns, static_cast<int64_t>(scene.views.size()) - 1);
  const SolidSamples after = samples(stream.stream().hull());
  const SolidComparison was = compareWithSolid(before), is = compareWithSolid(after);
  ASSERT_GT(was.cavity_filled_m3, 0.5 * was.cavity_m3);
  // As freeVoxels with the same points (test_refine): most of the pocket goes.
  EXPECT_LT(is.cavity_filled_m3, 0.3 * was.cavity_filled_m3);
  EXPECT_LE(falseCarvedFraction(before, after), 0.005);
  stream.reset();
  EXPECT_FALSE(stream.stream().hasHull());
  EXPECT_EQ(stream.storedPoints(), 0u);
  EXPECT_EQ(stream.freeVoxelCount(), 0u);
  for (size_t v = 0; v < scene.views.size(); ++v) addView(&stream, v);
  EXPECT_FALSE(stream.refineDue()) << "the points were forgotten by the reset";
}

TEST_F(CupStream, ATreeThatStartsAnewIsCarvedAgain) {
  PointCarvedStream stream(streamConfig(6), {});
  for (uint32_t v = 0; v < scene.views.size(); ++v) addPoints(&stream, v);
  size_t restarts = 0;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    const bool had_hull = stream.stream().hasHull();
    const uint64_t generation = stream.stream().hullGeneration();
    addView(&stream, v);
    if (!stream.stream().hasHull()) continue;
    const bool restarted = !had_hull || stream.stream().hullGeneration() != generation;
    restarts += restarted;
    ASSERT_EQ(stream.refineDue(), restarted) << "view " << v;
    if (restarted) {
      EXPECT_GT(stream.refine().free_voxels, 0u) << "view " << v;
    }
    EXPECT_EQ(stream.freeVoxelCount(), stream.stream().hull().freeVoxelCount()) << "view " << v;
  }
  EXPECT_GE(restarts, 2u) << "the first box and at least one refit";
}

TEST(PointCarvedStream, KeepsAtMostTheSetNumberOfPointsAndOnlyWellReprojectedOnes) {
  PointCarvingConfig config;
  config.max_surface_points = 10;
  config.surface_points.max_reprojection_px = 1.0;
  PointCarvedStream stream(streamConfig(5), config);
  const PinholeCamera camera;
  std::vector<SurfacePoint> points(6);
  points[0].reprojection_px = 2.0;
  points[1].reprojection_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 0.0), 4u);
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 1.0), 4u);
  EXPECT_EQ(stream.storedPoints(), 8u);
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 2.0), 4u);
  EXPECT_EQ(stream.storedPoints(), 8u) << "the oldest pair goes";
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, std::vector<SurfacePoint>(30), 3.0), 30u);
  EXPECT_EQ(stream.storedPoints(), 30u) << "the newest pair stays whole";
  config.max_surface_points = 0;
  EXPECT_THROW(PointCarvedStream(streamConfig(5), config), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
