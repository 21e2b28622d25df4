// Dense matching along epipolar lines (src/core/refine/dense_matching.cpp) against the renderer's
// depth maps: matches on the true surface, the same on any number of threads, and the cup's
// pocket carved by them as far as pairs of views can see into it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <stdexcept>

#include "concave_scene.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/refine/dense_matching.h"
#include "sift_hull/refine/free_space.h"

namespace sift_hull {
namespace {

/// Dense matching on, every fourth pixel.
DenseMatchConfig on() {
  DenseMatchConfig config;
  config.grid_step_px = 4;
  return config;
}

ConcaveScene& cup() {
  static ConcaveScene scene("cup", 7);
  return scene;
}

/// Each view with its two nearest by camera centre, as `hull --match-pairs neighbours` pairs them.
std::vector<std::pair<uint32_t, uint32_t>> neighbourPairs(const std::vector<PinholeCamera>& cams) {
  std::set<std::pair<uint32_t, uint32_t>> pairs;
  for (uint32_t a = 0; a < cams.size(); ++a) {
    std::vector<uint32_t> others;
    for (uint32_t b = 0; b < cams.size(); ++b) {
      if (b != a) others.push_back(b);
    }
    std::sort(others.begin(), others.end(), [&](uint32_t x, uint32_t y) {
      return (cams[x].centre() - cams[a].centre()).norm() <
             (cams[y].centre() - cams[a].centre()).norm();
    });
    for (size_t k = 0; k < 2; ++k) pairs.insert({std::min(a, others[k]), std::max(a, others[k])});
  }
  return {pairs.begin(), pairs.end()};
}

/// Exact points of view a's depth map (every step-th pixel) that view b sees too (its depth map
/// agrees within 1 %): the most any matching of the pair can find.
std::vector<SurfacePoint> covisiblePoints(const std::vector<RenderedView>& views, uint32_t a,
                                          uint32_t b, int step) {
  std::vector<SurfacePoint> points;
  const PinholeCamera& ca = views[a].view.camera;
  const PinholeCamera& cb = views[b].view.camera;
  for (int y = 0; y < views[a].depth.rows; y += step) {
    for (int x = 0; x < views[a].depth.cols; x += step) {
      const float d = views[a].depth.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const Eigen::Vector3d X = ca.backProject(Eigen::Vector2d(x, y), d);
      const Eigen::Vector2d px = cb.project(X);
      const int u = static_cast<int>(std::lround(px.x())),
                v = static_cast<int>(std::lround(px.y()));
      if (u < 0 || v < 0 || u >= views[b].depth.cols || v >= views[b].depth.rows) continue;
      const float seen = views[b].depth.at<float>(v, u);
      if (!(std::abs(seen - cb.depth(X)) < 0.01 * seen)) continue;
      SurfacePoint point;
      point.X_W = X;
      point.views = {a, b};
      points.push_back(point);
    }
  }
  return points;
}

/// The cup's pocket left in the hull after carving with `points` (of its fill before), and the
/// false carving.
std::pair<double, double> pocketLeft(const std::vector<SurfacePoint>& points) {
  ConcaveScene scene("cup", 7);
  const SolidPredicate inside = [&](const Eigen::Vector3d& X) { return scene.shape.contains(X); };
  const Shape filled = scene.shape.withoutCuts();
  const SolidPredicate cavity = [&](const Eigen::Vector3d& X) {
    return filled.contains(X) && !scene.shape.contains(X);
  };
  const SolidSamples before = sampleAgainstSolid(scene.hull.hull, inside, 96, cavity);
  scene.hull.hull.carveFree(freeVoxels(scene.hull.hull, camerasOf(scene.views), points, {}));
  const SolidSamples after = sampleAgainstSolid(scene.hull.hull, inside, 96, cavity);
  EXPECT_TRUE(checkMesh(scene.hull.hull.mesh()).watertight);
  return {compareWithSolid(after).cavity_filled_m3 / compareWithSolid(before).cavity_filled_m3,
          falseCarvedFraction(before, after)};
}

TEST(DenseMatches, LieOnTheTrueSurfaceAndDoNotDependOnThreads) {
  // Two neighbours of a ring of 36 views at 640x480, 10 degrees apart; the 20 views' hull bounds
  // the search.
  SceneConfig config = ConcaveScene::config("cup");
  config.width_px = 640, config.height_px = 480;
  config.layout = "ring", config.views = 36;
  const RenderedView view_l = renderSceneView(config, 0), view_r = renderSceneView(config, 1);
  const PinholeCamera& cl = view_l.view.camera;
  const PinholeCamera& cr = view_r.view.camera;
  const VisualHull& hull = cup().hull.hull;
  const DenseView left = denseMatchingView(view_l.image, view_l.mask, 3);
  const DenseView right = denseMatchingView(view_r.image, view_r.mask, 3);
  const PairMatches one = denseMatches(left, right, cl, cr, 0, 1, hull, on(), 1);
  const PairMatches two = denseMatches(left, right, cl, cr, 0, 1, hull, on(), 2);
  EXPECT_EQ(one.left_px, two.left_px);
  EXPECT_EQ(one.right_px, two.right_px);
  EXPECT_TRUE(one.left_keypoint.empty());
  const std::vector<SurfacePoint> points = triangulatePair(cl, cr, one);
  ASSERT_EQ(points.size(), one.left_px.size());
  size_t on_surface = 0;
  std::vector<double> errs;
  const double tolerance_m = hull.cube().resolution_m;
  for (size_t m = 0; m < points.size(); ++m) {
    const Eigen::Vector2d& px = one.left_px[m];
    const float truth = view_l.depth.at<float>(static_cast<int>(px.y()), static_cast<int>(px.x()));
    if (std::abs(cl.depth(points[m].X_W) - truth) < tolerance_m) ++on_surface;
    errs.push_back(std::abs(cl.depth(points[m].X_W) - truth));
  }
  std::sort(errs.begin(), errs.end());
  ASSERT_FALSE(errs.empty());
  std::cout << "depth error: median " << errs[errs.size() / 2] << " m, 90th percentile "
            << errs[errs.size() * 9 / 10] << " m\n";
  std::cout << one.left_px.size() << " dense matches, " << on_surface << " within " << tolerance_m
            << " m of the surface\n";
  EXPECT_GT(one.left_px.size(), 300u);
  // Measured: 3416 matches, median 3.3 mm, 90th percentile 12 mm (a voxel: 13 mm).
  EXPECT_GT(on_surface, 0.85 * static_cast<double>(one.left_px.size()));
  DenseMatchConfig off;
  off.grid_step_px = 0;
  EXPECT_TRUE(denseMatches(left, right, cl, cr, 0, 1, hull, off, 1).left_px.empty());
}

// What pairs of views can carve: exact points that both views of a neighbour pair see (the most
// any matching of the pairs can find) against exact points of each view alone.
TEST(PairCovisiblePoints, CarveLessOfThePocketThanEachViewsOwnPoints) {
  const ConcaveScene& scene = cup();
  const std::vector<PinholeCamera> cameras = camerasOf(scene.views);
  std::vector<SurfacePoint> exact;
  for (const auto& [a, b] : neighbourPairs(cameras)) {
    for (const SurfacePoint& p : covisiblePoints(scene.views, a, b, 4)) exact.push_back(p);
    for (const SurfacePoint& p : covisiblePoints(scene.views, b, a, 4)) exact.push_back(p);
  }
  const auto [pair_left, pair_false] = pocketLeft(exact);
  const auto [single_left, single_false] = pocketLeft(depthMapPoints(scene.views, 4));
  std::cout << "pocket left after carving: exact points both views of a neighbour pair see "
            << pair_left << " (false carving " << pair_false
            << "), exact points of each view alone " << single_left << '\n';
  // Measured at 320x240, depth 7: 0.69 and 0.24.
  EXPECT_LT(pair_left, 0.8);
  EXPECT_LT(single_left, pair_left);
  EXPECT_LE(pair_false, 0.005);
  EXPECT_LE(single_false, 0.005);
}

TEST(DenseMatches, RefuseBadSettingsAndImages) {
  const ConcaveScene& scene = cup();
  const RenderedView& view = scene.views[0];
  const DenseView dense = denseMatchingView(view.image, view.mask, 3);
  ASSERT_EQ(dense.grey.type(), CV_32FC1);
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(dense.grey, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.0);
  // The patch inside: the silhouette shrunk by the patch's radius.
  EXPECT_LT(cv::countNonZero(dense.inside), cv::countNonZero(view.mask));
  EXPECT_GT(cv::countNonZero(dense.inside), cv::countNonZero(view.mask) / 2);
  EXPECT_THROW(denseMatchingView(cv::Mat(), view.mask, 3), std::invalid_argument);
  EXPECT_THROW(denseMatchingView(cv::Mat(4, 4, CV_32FC1), view.mask, 3), std::invalid_argument);
  EXPECT_THROW(denseMatchingView(cv::Mat(4, 4, CV_8UC2), view.mask, 3), std::invalid_argument);
  EXPECT_THROW(denseMatchingView(view.image, cv::Mat(), 3), std::invalid_argument);
  EXPECT_THROW(denseMatchingView(view.image, view.mask, 0), std::invalid_argument);
  const PinholeCamera& camera = view.view.camera;
  const auto run = [&](const DenseView& left, const DenseMatchConfig& config) {
    return denseMatches(left, dense, camera, scene.views[1].view.camera, 0, 1, scene.hull.hull,
                        config, 1);
  };
  EXPECT_THROW(run(DenseView{}, on()), std::invalid_argument);
  const auto bad = [&](auto edit) {
    DenseMatchConfig config = on();
    edit(config);
    EXPECT_THROW(run(dense, config), std::invalid_argument);
  };
  bad([](DenseMatchConfig& c) { c.grid_step_px = -1; });
  bad([](DenseMatchConfig& c) { c.patch_radius_px = 0; });
  bad([](DenseMatchConfig& c) { c.min_ncc = std::nan(""); });
  bad([](DenseMatchConfig& c) { c.min_ncc = 1.5; });
  bad([](DenseMatchConfig& c) { c.min_ncc_margin = -0.1; });
  bad([](DenseMatchConfig& c) { c.min_patch_std = 2.0; });
  bad([](DenseMatchConfig& c) { c.max_round_trip_px = 0.0; });
  bad([](DenseMatchConfig& c) { c.max_round_trip_px = INFINITY; });
}

}  // namespace
}  // namespace sift_hull
