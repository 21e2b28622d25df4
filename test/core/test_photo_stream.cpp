// PhotoStream (the hull node's photo carving) against photoCarve on the same hull and views: a
// pass on a copy of the hull finds the same free voxels and colours its mesh; passes are due only
// when something changed; reset() discards a pass that runs; views are bounded and checked.
// VisualHull::clone is a deep copy.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <set>
#include <tuple>
#include <vector>

#include "concave_scene.h"
#include "sift_hull/mvs/photo_stream.h"

namespace sift_hull {
namespace {

constexpr int kDepth = 6;

/// The defaults (depth maps at half size) with fewer planes and rounds: the pass is compared with
/// photoCarve on the same settings, not with the truth, so the quicker depth maps suffice.
PhotoStreamConfig streamConfig() {
  PhotoStreamConfig config;
  config.carve.photo_depth_planes = 16;
  config.carve.photo_patch_match_rounds = 1;
  return config;
}

std::set<std::tuple<int, int, int>> voxelSet(const std::vector<Eigen::Vector3i>& voxels) {
  std::set<std::tuple<int, int, int>> set;
  for (const Eigen::Vector3i& v : voxels) set.emplace(v.x(), v.y(), v.z());
  return set;
}

/// A stream whose passes signal their end.
struct Signalled {
  explicit Signalled(PhotoStreamConfig config)
      : stream(config, [this] {
          std::lock_guard<std::mutex> lock(mutex);
          if (!ended_set) ended.set_value();
          ended_set = true;
        }) {}
  /// Whether the pass started ended within the deadline; ready for the next one after.
  bool waitForEnd() {
    const bool done =
        ended.get_future().wait_for(std::chrono::seconds(120)) == std::future_status::ready;
    std::lock_guard<std::mutex> lock(mutex);
    ended = std::promise<void>();
    ended_set = false;
    return done;
  }
  std::mutex mutex;
  std::promise<void> ended;
  bool ended_set = false;
  PhotoStream stream;
};

TEST(VisualHullClone, IsADeepCopy) {
  ConcaveScene scene("cup", kDepth);
  const VisualHull& hull = scene.hull.hull;
  VisualHull copy = hull.clone();
  const HullStats before = hull.stats();
  EXPECT_EQ(copy.stats().nodes, before.nodes);
  EXPECT_EQ(copy.stats().occupied_volume_m3, before.occupied_volume_m3);
  EXPECT_EQ(copy.mesh().faces.size(), hull.mesh().faces.size());
  EXPECT_EQ(copy.views().size(), hull.views().size());
  // Carving the copy leaves the original as it was.
  std::vector<Eigen::Vector3i> free;
  for (int i = 20; i < 40; ++i) free.emplace_back(i, 32, 32);
  copy.carveFree(free);
  EXPECT_GT(copy.freeVoxelCount(), 0u);
  EXPECT_EQ(hull.freeVoxelCount(), 0u);
  EXPECT_EQ(hull.stats().nodes, before.nodes);
  EXPECT_EQ(hull.stats().occupied_volume_m3, before.occupied_volume_m3);
  EXPECT_LT(copy.stats().occupied_volume_m3, before.occupied_volume_m3);
}

TEST(PhotoStream, APassFindsWhatPhotoCarveFindsAndColoursTheMesh) {
  ConcaveScene scene("cup", kDepth);
  const PhotoStreamConfig config = streamConfig();
  Signalled signalled(config);
  PhotoStream& stream = signalled.stream;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    ASSERT_TRUE(stream.add("view_" + std::to_string(v), scene.views[v].view.camera,
                           scene.views[v].image, scene.views[v].mask));
  }
  ASSERT_TRUE(stream.startIfDue(scene.hull.hull, 7));
  EXPECT_FALSE(stream.startIfDue(scene.hull.hull, 7)) << "a second pass while one runs";
  ASSERT_TRUE(signalled.waitForEnd()) << "the pass did not end";
  const std::unique_ptr<PhotoStream::Pass> pass = stream.takeDone();
  ASSERT_TRUE(pass);
  EXPECT_EQ(pass->error, "");
  EXPECT_EQ(pass->generation, 7u);
  EXPECT_EQ(pass->views, scene.views.size());
  EXPECT_TRUE(pass->carving.depths.empty()) << "the depth maps are not kept";

  PhotoViews views;
  for (const RenderedView& view : scene.views) views.cameras.push_back(view.view.camera);
  views.image = [&](uint32_t v) { return scene.views[v].image; };
  views.mask = [&](uint32_t v) { return scene.views[v].mask; };
  const PhotoCarveResult direct = photoCarve(scene.hull.hull, views, config.carve);
  ASSERT_GT(direct.free_voxels.size(), 0u);
  EXPECT_EQ(voxelSet(pass->carving.free_voxels), voxelSet(direct.free_voxels));
  EXPECT_EQ(scene.hull.hull.freeVoxelCount(), 0u) << "the pass carved the hull, not a copy";
  ASSERT_EQ(pass->mesh.colours_rgb.size(), pass->mesh.vertices_W.size());
  EXPECT_GT(pass->colouring.coloured_vertices, pass->mesh.vertices_W.size() / 2);

  // Nothing new: no pass; a new tree or a new view: one.
  EXPECT_FALSE(stream.startIfDue(scene.hull.hull, 7));
  EXPECT_TRUE(stream.startIfDue(scene.hull.hull, 8));
  ASSERT_TRUE(signalled.waitForEnd());
  EXPECT_TRUE(stream.takeDone());
  stream.remove("view_3");
  EXPECT_EQ(stream.keptViews(), scene.views.size() - 1);
  EXPECT_TRUE(stream.startIfDue(scene.hull.hull, 8));
  ASSERT_TRUE(signalled.waitForEnd());
  EXPECT_EQ(stream.takeDone()->views, scene.views.size() - 1);
  EXPECT_EQ(stream.passes(), 3u);
}

TEST(PhotoStream, ResetDiscardsTheRunningPass) {
  ConcaveScene scene("cup", kDepth);
  Signalled signalled(streamConfig());
  PhotoStream& stream = signalled.stream;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    stream.add("view_" + std::to_string(v), scene.views[v].view.camera, scene.views[v].image,
               scene.views[v].mask);
  }
  ASSERT_TRUE(stream.startIfDue(scene.hull.hull, 1));
  stream.reset();
  EXPECT_EQ(stream.keptViews(), 0u);
  ASSERT_TRUE(signalled.waitForEnd());
  EXPECT_FALSE(stream.takeDone()) << "a pass begun before reset() was handed over";
  EXPECT_FALSE(stream.startIfDue(scene.hull.hull, 1)) << "a pass without views";
}

TEST(PhotoStream, KeepsAtMostMaxViewsAndRefusesImagesThatDoNotFit) {
  ConcaveScene scene("cup", 4);
  PhotoStreamConfig config = streamConfig();
  config.photo_max_views = 3;
  PhotoStream stream(config, {});
  const RenderedView& view = scene.views[0];
  EXPECT_FALSE(stream.startIfDue(scene.hull.hull, 1)) << "no views";
  EXPECT_THROW(stream.add("small mask", view.view.camera, view.image,
                          cv::Mat(view.mask, cv::Rect(0, 0, 100, 100)).clone()),
               std::invalid_argument);
  cv::Mat sixteen;
  view.image.convertTo(sixteen, CV_16UC3);
  EXPECT_THROW(stream.add("16 bit", view.view.camera, sixteen, view.mask), std::invalid_argument);
  EXPECT_THROW(stream.add("colour mask", view.view.camera, view.image, view.image),
               std::invalid_argument);
  EXPECT_TRUE(stream.add("a", view.view.camera, view.image, view.mask));
  EXPECT_FALSE(stream.startIfDue(scene.hull.hull, 1)) << "one view";
  cv::Mat grey;
  cv::cvtColor(view.image, grey, cv::COLOR_BGR2GRAY);
  EXPECT_TRUE(stream.add("b", scene.views[1].view.camera, grey, scene.views[1].mask));
  EXPECT_TRUE(
      stream.add("c", scene.views[2].view.camera, scene.views[2].image, scene.views[2].mask));
  EXPECT_FALSE(
      stream.add("d", scene.views[3].view.camera, scene.views[3].image, scene.views[3].mask));
  EXPECT_EQ(stream.keptViews(), 3u);
  EXPECT_EQ(stream.leftOutViews(), 1u);
  PhotoStreamConfig bad = streamConfig();
  bad.photo_max_views = 1;
  EXPECT_THROW(PhotoStream(bad, {}), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
