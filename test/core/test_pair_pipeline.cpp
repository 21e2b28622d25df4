// src/core/pipeline against the renderer's ground truth: a calibrated pair of rendered views
// through runPair (kept matches judged by the depth maps, surface points on the true surface),
// and the matches refinement of the scene's hull (points on the surface, nothing of the solid
// carved).

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>

#include "concave_scene.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/pipeline/match_refinement.h"
#include "sift_hull/pipeline/pair_pipeline.h"

namespace sift_hull {
namespace {

/// Fraction of the points whose depth in view `view` lies within `relative` of the rendered
/// depth at their pixel.
double shareOnSurface(const std::vector<SurfacePoint>& points, const RenderedView& view,
                      double relative) {
  size_t near = 0;
  for (const SurfacePoint& point : points) {
    const Eigen::Vector2d px = view.view.camera.project(point.X_W);
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= view.depth.cols || v >= view.depth.rows) continue;
    const double truth = view.depth.at<float>(v, u);
    if (std::abs(view.view.camera.depth(point.X_W) - truth) <= relative * truth) ++near;
  }
  return points.empty() ? 0.0 : static_cast<double>(near) / points.size();
}

/// Relative depth error of a point "on the surface" in the refinement check.
constexpr double kSurfaceTolerance = 0.02;

class PairPipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<ConcaveScene>("cup", 6);
    SceneConfig config;  // a ring of 24 views, 15 degrees apart: a pair of neighbours
    config.views = 24;
    pair_views_ = {renderSceneView(config, 0), renderSceneView(config, 1)};
  }
  static void TearDownTestSuite() { scene_.reset(); }

  /// Two neighbouring views of the default shape at 640x480, with their cameras.
  PairInput pairInput() const {
    PairInput input;
    input.left_image = pair_views_[0].image, input.right_image = pair_views_[1].image;
    input.cameras = std::make_pair(pair_views_[0].view.camera, pair_views_[1].view.camera);
    input.left_view = 3, input.right_view = 5;
    return input;
  }

  /// Guided matching along the epipolar lines (the refinement's).
  static PairPipelineConfig guided() {
    PairPipelineConfig config;
    config.epipolar_search_px = 2.0;
    return config;
  }

  static std::unique_ptr<ConcaveScene> scene_;  ///< the refinement's scene and hull
  static std::vector<RenderedView> pair_views_;
};

std::unique_ptr<ConcaveScene> PairPipelineTest::scene_;
std::vector<RenderedView> PairPipelineTest::pair_views_;

TEST_F(PairPipelineTest, KeptMatchesAreCorrectAndTheirPointsLieOnTheSurface) {
  const PairInput input = pairInput();
  const auto best = makeFilter("best", FilterConfigs());
  const auto ratio = makeFilter("ratio", FilterConfigs());
  const PairResult pair = runPair(input, PairPipelineConfig(), {best.get(), ratio.get()});
  ASSERT_TRUE(pair.why_not.empty()) << pair.why_not;
  ASSERT_EQ(pair.verdicts.size(), 2u);
  EXPECT_EQ(pair.verdicts[0].name, best->name());
  EXPECT_EQ(pair.verdicts[1].name, ratio->name());
  ASSERT_TRUE(pair.putative.F_right_left.has_value());  // calibrated by the cameras
  const FilterResult& kept = pair.verdicts[0].result;
  ASSERT_EQ(kept.keep.size(), pair.putative.matches.size());
  EXPECT_EQ(pair.kept.left_view, input.left_view);
  EXPECT_EQ(pair.kept.left_px.size(), kept.keptCount());
  EXPECT_EQ(pair.kept.left_keypoint.size(), pair.kept.left_px.size());

  const RenderedView &left = pair_views_[0], &right = pair_views_[1];
  const std::vector<MatchTruth> truth = judgeBySceneDepth(
      pair.putative, {left.view.camera, left.depth}, {right.view.camera, right.depth});
  size_t correct = 0, wrong = 0;
  for (size_t m = 0; m < truth.size(); ++m) {
    if (!kept.keep[m]) continue;
    correct += truth[m] == MatchTruth::kCorrect;
    wrong += truth[m] == MatchTruth::kWrong;
  }
  const double precision = static_cast<double>(correct) / std::max<size_t>(correct + wrong, 1);
  const double on_surface = shareOnSurface(pair.surface_points, left, 0.01);
  std::cout << pair.putative.matches.size() << " putative, " << pair.kept.left_px.size()
            << " kept, precision " << precision << ", " << pair.surface_points.size() << " points, "
            << on_surface << " within 1 % of the true depth\n";
  EXPECT_GE(correct, 30u);
  EXPECT_GE(precision, 0.9);
  EXPECT_GE(pair.surface_points.size(), 30u);
  EXPECT_GE(on_surface, 0.9);
  for (const SurfacePoint& point : pair.surface_points) {
    EXPECT_EQ(point.views, (std::vector<uint32_t>{input.left_view, input.right_view}));
  }
}

TEST_F(PairPipelineTest, TheCacheDescribesEachImageOnceAndChangesNothing) {
  const auto best = makeFilter("best", FilterConfigs());
  FeatureCache cache(4);
  const PairResult first = runPair(pairInput(), guided(), {best.get()}, &cache);
  const PairResult again = runPair(pairInput(), guided(), {best.get()}, &cache);
  EXPECT_EQ(cache.misses(), 2u);
  EXPECT_EQ(cache.hits(), 2u);
  EXPECT_EQ(first.verdicts[0].result.keep, again.verdicts[0].result.keep);
  EXPECT_GT(first.surface_points.size(), 0u);
  EXPECT_EQ(first.surface_points.size(), again.surface_points.size());
}

TEST_F(PairPipelineTest, WithoutCamerasNothingIsTriangulatedAndGuidedMatchingNeedsThem) {
  PairInput input = pairInput();
  input.cameras.reset();
  const auto best = makeFilter("best", FilterConfigs());
  // No cameras: every descriptor matched, as without guided matching.
  const PairResult pair = runPair(input, guided(), {best.get()});
  EXPECT_FALSE(pair.putative.F_right_left.has_value());
  EXPECT_TRUE(pair.surface_points.empty());
  EXPECT_GT(pair.putative.matches.size(), 0u);
  EXPECT_EQ(pair.putative.matches.size(),
            runPair(input, PairPipelineConfig(), {best.get()}).putative.matches.size());
  input.F_right_left = Eigen::Matrix3d::Identity();
  EXPECT_EQ(runPair(input, guided(), {best.get()}).putative.F_right_left, input.F_right_left);
}

TEST_F(PairPipelineTest, RefusesBadInput) {
  const auto best = makeFilter("best", FilterConfigs());
  EXPECT_THROW(runPair(pairInput(), PairPipelineConfig(), {}), std::invalid_argument);
  EXPECT_THROW(runPair(pairInput(), PairPipelineConfig(), {nullptr}), std::invalid_argument);
  PairPipelineConfig bad;
  bad.epipolar_search_px = -1.0;
  EXPECT_THROW(runPair(pairInput(), bad, {best.get()}), std::invalid_argument);
  PairInput empty = pairInput();
  empty.right_image = cv::Mat();
  EXPECT_THROW(runPair(empty, PairPipelineConfig(), {best.get()}), std::invalid_argument);
  EXPECT_THROW(keptPairMatches(PutativeMatches(), {1}, 0, 1), std::invalid_argument);
}

TEST_F(PairPipelineTest, TheMatchesRefinementFindsTheSurfaceAndCarvesNothingOfTheSolid) {
  RefineViews views;
  views.cameras = camerasOf(scene_->views);
  views.image = [](uint32_t view) { return scene_->views.at(view).image; };
  const auto best = makeFilter("best", FilterConfigs());
  const MatchRefineConfig config;
  const MatchRefineResult refined = refineWithMatches(views, scene_->hull.hull, *best, config);
  EXPECT_EQ(refined.view_pairs, refinementViewPairs(views.cameras, ViewPairing::kNeighbours));
  ASSERT_EQ(refined.pairs.size(), refined.view_pairs.size());  // no dense matching by default
  EXPECT_EQ(refined.dense_matches, 0u);
  ASSERT_GE(refined.points.size(), 100u);
  size_t near = 0;
  for (const SurfacePoint& point : refined.points) {
    near += shareOnSurface({point}, scene_->views[point.views[0]], kSurfaceTolerance) > 0.0;
  }
  EXPECT_GE(static_cast<double>(near) / refined.points.size(), 0.95);

  // The free space of the same matches, asked for alone, is the refinement's.
  MatchRefineResult alone;
  surfacePointsAndFreeSpace(views.cameras, refined.pairs, scene_->hull.hull, config, &alone);
  EXPECT_EQ(alone.free_voxels, refined.free_voxels);
  EXPECT_EQ(alone.counts.kept, refined.counts.kept);

  HullResult hull = buildHull(hullInputOf(scene_->views), ConcaveScene::depth(6));
  const SolidPredicate inside = [](const Eigen::Vector3d& X) { return scene_->shape.contains(X); };
  const SolidSamples before = sampleAgainstSolid(hull.hull, inside, 64);
  hull.hull.carveFree(refined.free_voxels);
  const double false_carved =
      falseCarvedFraction(before, sampleAgainstSolid(hull.hull, inside, 64));
  std::cout << refined.points.size() << " points (" << near << " within " << 100 * kSurfaceTolerance
            << " % of the rendered depth), " << refined.free_voxels.size()
            << " free voxels, false carving " << false_carved << '\n';
  EXPECT_LE(false_carved, 0.005);
}

}  // namespace
}  // namespace sift_hull
