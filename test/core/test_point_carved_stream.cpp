// PointCarvedStream: a streamed hull that surface points arriving pair by pair carve, checked
// against the renderer's ground truth (the concave scenes' true solids).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

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

TEST_F(CupStream, ARefinementInSlicesCarvesWhatOneAtOnceCarves) {
  PointCarvedStream whole(streamConfig(6), {}), sliced(streamConfig(6), {});
  for (PointCarvedStream* stream : {&whole, &sliced}) {
    for (uint32_t v = 0; v < scene.views.size(); ++v) addPoints(stream, v);
    for (size_t v = 0; v < scene.views.size(); ++v) addView(stream, v);
  }
  const PointCarvedStream::Refinement at_once = whole.refine();
  PointCarvedStream::Refinement in_slices;
  size_t slices = 0;
  for (; slices < 100000 && !sliced.refineFor(1e-4, &in_slices); ++slices) {
    ASSERT_TRUE(sliced.refining());
    ASSERT_TRUE(sliced.refineDue()) << "a refinement not done is due";
    ASSERT_EQ(sliced.stream().hull().freeVoxelCount(), 0u) << "carved only at the last slice";
  }
  EXPECT_GE(slices, 5u) << "a 0.1 ms budget must take several slices";
  EXPECT_FALSE(sliced.refining());
  EXPECT_FALSE(sliced.refineDue());
  ASSERT_GT(at_once.free_voxels, 0u);
  EXPECT_EQ(in_slices.free_voxels, at_once.free_voxels);
  EXPECT_EQ(in_slices.points_used, at_once.points_used);
  std::vector<Eigen::Vector3i> a = whole.stream().hull().freeVoxels(),
                               b = sliced.stream().hull().freeVoxels();
  const auto order = [](const Eigen::Vector3i& p, const Eigen::Vector3i& q) {
    return std::tie(p.z(), p.y(), p.x()) < std::tie(q.z(), q.y(), q.x());
  };
  std::sort(a.begin(), a.end(), order);
  std::sort(b.begin(), b.end(), order);
  EXPECT_TRUE(a == b) << "the same free voxels";
  // A reset in the middle drops the refinement with everything else.
  for (uint32_t v = 0; v < scene.views.size(); ++v) addPoints(&sliced, v);
  ASSERT_FALSE(sliced.refineFor(1e-4, &in_slices));
  sliced.reset();
  EXPECT_FALSE(sliced.refining());
  EXPECT_FALSE(sliced.refineDue());
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
  config.max_points_per_pair = 20;
  config.surface_points.max_reprojection_px = 1.0;
  PointCarvedStream stream(streamConfig(5), config);
  const PinholeCamera camera;
  std::vector<SurfacePoint> points(6);
  points[0].reprojection_px = 2.0;
  points[1].reprojection_px = std::numeric_limits<double>::quiet_NaN();
  const PointCarvedStream::AddedPoints first = stream.addSurfacePoints(camera, camera, points, 0);
  EXPECT_EQ(first.kept, 4u);
  EXPECT_EQ(first.over_reprojection, 2u);
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 1).kept, 4u);
  EXPECT_EQ(stream.storedPoints(), 8u);
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 2).kept, 4u);
  EXPECT_EQ(stream.storedPoints(), 8u) << "the oldest pair goes";
  const PointCarvedStream::AddedPoints large =
      stream.addSurfacePoints(camera, camera, std::vector<SurfacePoint>(30), 3);
  EXPECT_EQ(large.kept, 20u) << "subsampled to max_points_per_pair";
  EXPECT_EQ(large.subsampled, 10u);
  EXPECT_EQ(stream.storedPoints(), 20u) << "the newest pair stays whole";
  config.max_surface_points = 0;
  EXPECT_THROW(PointCarvedStream(streamConfig(5), config), std::invalid_argument);
}

TEST(PointCarvedStream, SubsamplesALargePairEvenlyInItsOrder) {
  PointCarvingConfig config;
  config.max_points_per_pair = 4;
  PointCarvedStream stream(streamConfig(5), config);
  std::vector<SurfacePoint> points(100);
  for (size_t i = 0; i < points.size(); ++i) points[i].X_W.x() = static_cast<double>(i);
  const PinholeCamera camera;
  EXPECT_EQ(stream.addSurfacePoints(camera, camera, points, 0).kept, 4u);
  EXPECT_EQ(stream.storedPoints(), 4u);
}

TEST_F(CupStream, AFarCameraOrPointIsRefusedAndTheCarvingGoesOn) {
  PointCarvedStream stream(streamConfig(6), {});
  for (size_t v = 0; v < scene.views.size(); ++v) addView(&stream, v);
  ASSERT_TRUE(stream.stream().hasHull());
  const PinholeCamera& near = scene.views[0].view.camera;
  const PinholeCamera far =
      PinholeCamera::fromCentre(near.K(), near.R(), Eigen::Vector3d(1e300, 0.0, 0.0));
  std::vector<SurfacePoint> points = pointsOfView(scene.views, 0);
  const PointCarvedStream::AddedPoints refused = stream.addSurfacePoints(near, far, points, 0);
  EXPECT_EQ(refused.kept, 0u);
  EXPECT_NE(refused.refused.find("max_distance_cube_edges"), std::string::npos) << refused.refused;
  EXPECT_FALSE(stream.refineDue()) << "nothing of the refused pair stays";
  SurfacePoint lost = points.front();
  lost.X_W = Eigen::Vector3d(0.0, 0.0, 1e30);
  points.push_back(lost);
  const PointCarvedStream::AddedPoints added = stream.addSurfacePoints(near, near, points, 1);
  EXPECT_EQ(added.outside, 1u);
  EXPECT_EQ(added.kept, points.size() - 1);
  ASSERT_TRUE(stream.refineDue());
  EXPECT_GT(stream.refine().free_voxels, 0u) << "the good pair still carves";
}

TEST_F(CupStream, ClearingABoxFreesItsOccupiedVoxelsInTheHullAndTheMesh) {
  PointCarvedStream stream(streamConfig(6), {});
  for (size_t v = 0; v < scene.views.size(); ++v) addView(&stream, v);
  ASSERT_TRUE(stream.stream().hasHull());
  const VisualHull& hull = stream.stream().hull();
  const Box3d box = stream.stream().box();
  // The cube above the middle of the box.
  Box3d top = hull.cube().box();
  top.min_W.z() = box.centre().z();
  const size_t cleared = stream.clearBox(top);
  EXPECT_GT(cleared, 0u);
  EXPECT_EQ(stream.freeVoxelCount(), hull.freeVoxelCount());
  const double edge = hull.cube().resolution_m;
  size_t occupied_above = 0, occupied_below = 0;
  hull.forEachLeaf([&](const HullCell& cell) {
    if (cell.state == CellState::kOut) return;
    const double cell_edge = hull.cube().edge_m() / (1 << cell.depth);
    const double z_min = hull.cube().origin_W().z() + cell.index.z() * cell_edge;
    (z_min >= top.min_W.z() + edge ? occupied_above : occupied_below) += 1;
  });
  EXPECT_EQ(occupied_above, 0u) << "no occupied cell wholly inside the cleared box";
  EXPECT_GT(occupied_below, 0u) << "the rest stays";
  for (const Eigen::Vector3f& vertex : hull.mesh().vertices_W) {
    EXPECT_LE(vertex.z(), top.min_W.z() + edge) << "the mesh is cut at the box";
  }
  EXPECT_EQ(stream.clearBox(top), 0u) << "a cleared box has nothing more to clear";
  Box3d inverted = box;
  std::swap(inverted.min_W, inverted.max_W);
  EXPECT_THROW(stream.clearBox(inverted), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
