// The visual hull on synthetic scenes with known answers: signed distances, the LP box against
// dense carving, octree volume, mesh, incremental carving and the OctoMap output.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <tuple>

#include "common/test_data.h"
#include "sift_hull/eval/hull_evaluation.h"
#include "sift_hull/hull/distance_map.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

HullConfig depth(int max_depth) {
  HullConfig config;
  config.max_depth = max_depth;
  return config;
}

cv::Mat discMask(cv::Size size, cv::Point2d centre, double radius) {
  cv::Mat mask(size, CV_8UC1);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      mask.at<uint8_t>(v, u) = std::hypot(u - centre.x, v - centre.y) <= radius ? 255 : 0;
    }
  }
  return mask;
}

TEST(SignedDistanceMap, FollowsTheDiscsDistanceNearItAndBoundsItFarAway) {
  const cv::Point2d centre(60.3, 50.6);
  const double radius = 15.0;
  const int padding = 8;
  const cv::Mat disc = discMask({120, 100}, centre, radius);
  const SignedDistanceMap map(disc, silhouetteBounds(disc, false), padding);
  for (double u = -20; u < 140; u += 3.7) {
    for (double v = -20; v < 120; v += 2.9) {
      const double expected = std::hypot(u - centre.x, v - centre.y) - radius;
      const bool near =
          std::abs(u - centre.x) < radius + padding && std::abs(v - centre.y) < radius + padding;
      if (near) {
        EXPECT_NEAR(map.at(u, v), expected, 1.0) << "at " << u << ", " << v;
      } else {  // a lower bound, and outside
        EXPECT_LT(map.at(u, v), expected + 1.0) << "at " << u << ", " << v;
        EXPECT_GT(map.at(u, v), padding - 1.0) << "at " << u << ", " << v;
      }
    }
  }
}

TEST(SignedDistanceMap, PaddingDecidesWhatLiesOutsideTheImage) {
  // A disc cut by the left border: its left side is open unless the border bounds it.
  const cv::Mat mask = discMask({40, 40}, {2, 20}, 10);
  const SignedDistanceMap carving(mask, silhouetteBounds(mask, true), 4);
  const SignedDistanceMap keeping(mask, silhouetteBounds(mask, false), 4);
  EXPECT_GT(carving.at(-100, 20), 0.0f);
  EXPECT_LT(keeping.at(-100, 20), 0.0f);
  EXPECT_LT(keeping.at(-3, 20), 0.0f);
  EXPECT_GT(keeping.at(-3, 2), 0.0f);   // beyond the disc's bounded top side
  EXPECT_GT(keeping.at(20, 20), 0.0f);  // inside the image, outside the disc
}

TEST(HullCube, HoldsTheBoxWithAVoxelOfMarginOnTheVoxelGrid) {
  Box3d box;
  box.min_W = Eigen::Vector3d(-0.3, 0.1, 2.0);
  box.max_W = Eigen::Vector3d(0.5, 0.4, 2.2);
  for (int depth : {3, 7, 9}) {
    const HullCube cube = HullCube::around(box, depth);
    EXPECT_NEAR(cube.resolution_m, 0.8 / ((1 << depth) - 3), 1e-12);
    const Box3d outer = cube.box();
    EXPECT_TRUE(((box.min_W - outer.min_W).array() >= cube.resolution_m - 1e-9).all());
    EXPECT_TRUE(((outer.max_W - box.max_W).array() >= cube.resolution_m - 1e-9).all());
  }
}

TEST(HullCube, TakesAResolutionInMetresAtTheLeastDepthThatHoldsTheBox) {
  Box3d box;
  box.min_W = Eigen::Vector3d(-0.3, 0.1, 2.0);
  box.max_W = Eigen::Vector3d(0.5, 0.4, 2.2);
  const HullCube cube = HullCube::withResolution(box, 0.01);  // 0.8 m: 83 cells, depth 7
  EXPECT_EQ(cube.resolution_m, 0.01);
  EXPECT_EQ(cube.depth, 7);
  const Box3d outer = cube.box();
  EXPECT_TRUE(((box.min_W - outer.min_W).array() >= cube.resolution_m - 1e-9).all());
  EXPECT_TRUE(((outer.max_W - box.max_W).array() >= cube.resolution_m - 1e-9).all());
  HullConfig config;
  config.resolution_m = 0.01;
  config.max_depth = 3;  // replaced
  EXPECT_EQ(HullCube::forConfig(box, config).depth, 7);
  EXPECT_EQ(VisualHull(box, config).cube().resolution_m, 0.01);
  try {
    HullCube::withResolution(box, 1e-4);  // 8000 cells: deeper than the octree goes
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("raise resolution_m (at least 0.00078"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(HullCube::withResolution(box, 1e308), std::invalid_argument) << "no finite edge";
  config.resolution_m = -1.0;
  EXPECT_THROW(validate(config), std::invalid_argument);
}

/// One scene carved at depth 7, with the dense reference at twice the resolution.
class SphereHull : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    result_ = new HullResult(buildHull(test::sceneHullInput("sphere", 12), depth(7)));
    dense_ = new DenseGrid(denseCarving(result_->hull.views(), result_->hull.cube().box(), 256, 2));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete dense_;
  }
  static HullResult* result_;
  static DenseGrid* dense_;
};
HullResult* SphereHull::result_ = nullptr;
DenseGrid* SphereHull::dense_ = nullptr;

/// The LP box holds the dense hull (to a dense voxel) and exceeds it by at most 5 % of its edge.
void expectTightBox(const Box3d& box, const DenseGrid& dense_grid) {
  const Box3d dense = dense_grid.occupiedBounds();
  const double edge = box.size().maxCoeff();
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(box.min_W[axis], dense.min_W[axis] + dense_grid.voxel_m) << "axis " << axis;
    EXPECT_GE(box.max_W[axis], dense.max_W[axis] - dense_grid.voxel_m) << "axis " << axis;
    EXPECT_LE(dense.min_W[axis] - box.min_W[axis], 0.05 * edge) << "axis " << axis;
    EXPECT_LE(box.max_W[axis] - dense.max_W[axis], 0.05 * edge) << "axis " << axis;
  }
}

TEST_F(SphereHull, LpBoxHoldsTheDenseHullAndExceedsItByAtMostFivePercent) {
  expectTightBox(result_->box, *dense_);
}

TEST_F(SphereHull, VolumeMatchesDenseCarvingAtTwiceTheResolution) {
  EXPECT_GE(volumeIoU(result_->hull, *dense_), 0.99);
}

TEST_F(SphereHull, MeshIsWatertightAndReprojectsOntoEverySilhouette) {
  EXPECT_TRUE(result_->mesh_check.watertight)
      << result_->mesh_check.boundary_edges << " boundary, "
      << result_->mesh_check.non_manifold_edges << " non-manifold edges";
  const ReprojectionIoU iou = reprojectionIoU(result_->mesh, result_->hull.views());
  EXPECT_GE(iou.min, 0.99);
}

TEST_F(SphereHull, MeshLiesNearTheSphere) {
  // Twelve views leave the hull a little larger than the sphere (radius 0.8 m).
  const double voxel = result_->hull.cube().resolution_m;
  EXPECT_LT(meanDistanceToSphere(result_->mesh, Eigen::Vector3d::Zero(), 0.8), 2.0 * voxel);
}

TEST(VisualHull, SampledFieldIsTheMaximumOverEveryView) {
  // sampleField looks up only the views that can hold the maximum in each tile of 8 voxels;
  // valueAt looks up every view. At depth 8 a tile spans a few pixels, so most of the 24 views
  // are left out near the surface, where the points are taken.
  HullConfig config;
  config.max_depth = 8;
  const HullResult result = buildHull(test::ring(24), config);
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < result.mesh.vertices_W.size(); i += 5) {
    const Eigen::Vector3d vertex = result.mesh.vertices_W[i].cast<double>();
    for (double scale : {0.98, 1.0, 1.02}) points.push_back(scale * vertex);
  }
  std::vector<float> sampled;
  result.hull.sampleField(points, &sampled);
  ASSERT_EQ(sampled.size(), points.size());
  size_t differing = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    differing += sampled[i] != result.hull.valueAt(points[i]);
  }
  EXPECT_EQ(differing, 0u) << "of " << points.size();
}

double volumeOf(const octomap::OcTree& tree, int occupied) {  // occupied 1, free 0, either -1
  double m3 = 0.0;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (occupied < 0 || tree.isNodeOccupied(*leaf) == (occupied == 1)) {
      m3 += std::pow(leaf.getSize(), 3);
    }
  }
  return m3;
}

/// 1 occupied, 0 free, -1 unknown.
int stateAt(const octomap::OcTree& tree, const Eigen::Vector3d& X_W) {
  const octomap::OcTreeNode* node = tree.search(X_W.x(), X_W.y(), X_W.z());
  return node == nullptr ? -1 : tree.isNodeOccupied(node);
}

TEST_F(SphereHull, OctomapHoldsTheOccupiedAndTheCarvedCells) {
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(result_->hull);
  const HullCube& cube = result_->hull.cube();
  EXPECT_DOUBLE_EQ(tree->getResolution(), cube.resolution_m);
  EXPECT_EQ(stateAt(*tree, Eigen::Vector3d::Zero()), 1);  // the sphere's centre
  // A voxel in the cube's corner lies 1.3 m from the centre of the sphere (radius 0.8): carved.
  const Eigen::Vector3d corner =
      cube.origin_W() + Eigen::Vector3d::Constant(1.5 * cube.resolution_m);
  ASSERT_GT(corner.norm(), 1.2);
  EXPECT_EQ(stateAt(*tree, corner), 0);
  EXPECT_EQ(stateAt(*tree, cube.origin_W() - Eigen::Vector3d::Constant(0.5 * cube.resolution_m)),
            -1);  // outside the cube: never decided
  double hull_m3 = 0.0;
  const double voxel_m3 = std::pow(cube.resolution_m, 3);
  result_->hull.forEachLeaf([&](const HullCell& cell) {
    if (cell.state != CellState::kOut) hull_m3 += voxel_m3 * std::pow(8, 7 - cell.depth);
  });
  EXPECT_NEAR(volumeOf(*tree, 1), hull_m3, 1e-9 * hull_m3);
  const double cube_m3 = std::pow(cube.edge_m(), 3);  // the whole cube is known
  EXPECT_NEAR(volumeOf(*tree, -1), cube_m3, 1e-9 * cube_m3);
  // Free space as coarse leaves, pruned: far fewer leaves than free voxels.
  size_t free_leaves = 0;
  for (auto leaf = tree->begin_leafs(); leaf != tree->end_leafs(); ++leaf) {
    free_leaves += !tree->isNodeOccupied(*leaf);
  }
  const double free_voxels = (cube_m3 - hull_m3) / voxel_m3;
  EXPECT_GT(free_leaves, 0u);
  EXPECT_LT(free_leaves, free_voxels / 8) << free_voxels << " free voxels";
  const size_t leaves = tree->getNumLeafNodes();
  tree->prune();
  EXPECT_EQ(tree->getNumLeafNodes(), leaves) << "not pruned";
  // The hull's own volume (surface cells by their centre) lies close above the sphere's.
  const double sphere_m3 = 4.0 / 3.0 * M_PI * std::pow(0.8, 3);
  EXPECT_GT(result_->hull.stats().occupied_volume_m3, sphere_m3);
  EXPECT_LT(result_->hull.stats().occupied_volume_m3, 1.03 * sphere_m3);

  const std::string path = test::temporaryDirectory() + "/hull.bt";
  testing::internal::CaptureStderr();
  writeOctomap(*tree, path);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "") << "nothing on stderr (a --json run's)";
  octomap::OcTree read(path);
  EXPECT_EQ(read.getNumLeafNodes(), tree->getNumLeafNodes());
}

TEST_F(SphereHull, ClearingABoxFreesTheVoxelsItTouchesAndNothingElse) {
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(result_->hull);
  const double res = tree->getResolution();
  const double before_m3 = volumeOf(*tree, 1), known_m3 = volumeOf(*tree, -1);
  // Deep inside the sphere, not on voxel boundaries: the voxels touched are all occupied.
  const Box3d box{Eigen::Vector3d(-0.1, -0.07, 0.02), Eigen::Vector3d(0.13, 0.05, 0.21)};
  clearBox(box, tree.get());
  double touched = 1.0;
  for (int a = 0; a < 3; ++a) {
    touched *= std::floor(box.max_W[a] / res) - std::floor(box.min_W[a] / res) + 1;
  }
  EXPECT_NEAR(volumeOf(*tree, 1), before_m3 - touched * std::pow(res, 3), 1e-9 * before_m3);
  EXPECT_NEAR(volumeOf(*tree, -1), known_m3, 1e-9 * known_m3);  // unknown stays unknown
  EXPECT_EQ(stateAt(*tree, box.centre()), 0);
  EXPECT_EQ(stateAt(*tree, box.max_W + Eigen::Vector3d::Constant(1.01 * res)), 1);
  EXPECT_EQ(stateAt(*tree, Eigen::Vector3d(0.0, 0.0, -0.3)), 1);
  // A box reaching past the cube clears the cube's part only.
  const HullCube& cube = result_->hull.cube();
  const Eigen::Vector3d outside = cube.origin_W() - Eigen::Vector3d::Constant(0.5 * res);
  clearBox({outside - Eigen::Vector3d::Constant(res), outside + Eigen::Vector3d::Constant(2 * res)},
           tree.get());
  EXPECT_EQ(stateAt(*tree, outside), -1);
  EXPECT_NEAR(volumeOf(*tree, -1), known_m3, 1e-9 * known_m3);
  // Bad boxes are refused before anything changes.
  Box3d inverted = box;
  std::swap(inverted.min_W.x(), inverted.max_W.x());
  EXPECT_FALSE(isValidClearBox(inverted));
  EXPECT_THROW(clearBox(inverted, tree.get()), std::invalid_argument);
  EXPECT_THROW(clearBox({Eigen::Vector3d(std::nan(""), 0, 0), Eigen::Vector3d::Ones()}, tree.get()),
               std::invalid_argument);
  EXPECT_TRUE(isValidClearBox({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}));
}

TEST_F(SphereHull, WritesOctoMapsBinaryStreamByteForByte) {
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(result_->hull);
  std::stringstream ours, octomaps;
  writeOctomapBinaryData(*tree, ours);
  tree->writeBinaryNode(octomaps, tree->getRoot());
  ASSERT_GT(octomaps.str().size(), 1000u);
  EXPECT_EQ(ours.str(), octomaps.str());
  const octomap::OcTree empty(0.1);
  std::stringstream nothing;
  writeOctomapBinaryData(empty, nothing);
  EXPECT_EQ(nothing.str(), "");
}

/// The occupied leaves' centres of an OctoMap, sorted.
std::vector<std::array<double, 3>> sortedCentres(const std::vector<Eigen::Vector3d>& centres) {
  std::vector<std::array<double, 3>> sorted;
  for (const Eigen::Vector3d& c : centres) sorted.push_back({c.x(), c.y(), c.z()});
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

TEST(CompactOctomap, IsToOctomapsMapByteForByteAndLeafForLeaf) {
  // Depth 6 and 7 on two threads write the subtrees in parallel, on one thread in one walk.
  for (const auto& [shape, depth_levels, threads] :
       {std::tuple<const char*, int, int>{"sphere", 5, 2},
        {"sculpture", 6, 2},
        {"sculpture", 7, 2},
        {"sculpture", 7, 1}}) {
    HullConfig config = depth(depth_levels);
    config.threads = threads;
    const HullResult result = buildHull(test::sceneHullInput(shape, 8, "ring"), config);
    const std::unique_ptr<octomap::OcTree> tree = toOctomap(result.hull);
    std::stringstream reference;
    writeOctomapBinaryData(*tree, reference);
    const CompactOctomap compact = compactOctomap(result.hull);
    EXPECT_EQ(compact.resolution_m, tree->getResolution());
    ASSERT_GT(reference.str().size(), 100u);
    EXPECT_TRUE(compact.binary_data == reference.str())
        << shape << " depth " << depth_levels << ": " << compact.binary_data.size()
        << " bytes against " << reference.str().size();
    std::vector<Eigen::Vector3d> centres;
    for (auto leaf = tree->begin_leafs(); leaf != tree->end_leafs(); ++leaf) {
      if (tree->isNodeOccupied(*leaf)) centres.emplace_back(leaf.getX(), leaf.getY(), leaf.getZ());
    }
    const auto expected = sortedCentres(centres),
               actual = sortedCentres(compact.occupied_centres_W);
    ASSERT_EQ(actual.size(), expected.size());
    for (size_t i = 0; i < actual.size(); ++i) {
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(actual[i][a], expected[i][a], 1e-9) << i;
    }
    const CompactOctomap without = compactOctomap(result.hull, false);  // no centres wanted
    EXPECT_TRUE(without.binary_data == compact.binary_data && without.occupied_centres_W.empty());
  }
}

std::vector<HullCell> leavesOf(const VisualHull& hull) {
  std::vector<HullCell> leaves;
  hull.forEachLeaf([&](const HullCell& cell) { leaves.push_back(cell); });
  return leaves;
}

TEST(VisualHull, AddingViewsOneAtATimeGivesTheSameTreeAsAllAtOnce) {
  const HullInput input = test::sceneHullInput("sculpture", 8, "ring");
  const HullConfig config = depth(6);
  std::vector<HullView> views = makeHullViews(input.names, input.cameras, input.masks, config);
  const Box3d box = boundingBoxOf(views);
  VisualHull at_once(box, config), one_by_one(box, config);
  at_once.addViews(views);
  for (const HullView& view : views) one_by_one.addView(view);
  const std::vector<HullCell> expected = leavesOf(at_once), actual = leavesOf(one_by_one);
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < actual.size(); ++i) {
    EXPECT_EQ(actual[i].index, expected[i].index);
    EXPECT_EQ(actual[i].depth, expected[i].depth);
    EXPECT_EQ(actual[i].state, expected[i].state);
    if (actual[i].state != CellState::kOut) {
      EXPECT_EQ(actual[i].centre_value, expected[i].centre_value);
    }
  }
}

TEST(VisualHull, BoxShapeMatchesDenseCarving) {
  const HullResult result = buildHull(test::sceneHullInput("box", 10), depth(7));
  const DenseGrid dense = denseCarving(result.hull.views(), result.hull.cube().box(), 256, 2);
  EXPECT_GE(volumeIoU(result.hull, dense), 0.99);
  EXPECT_TRUE(result.mesh_check.watertight);
  EXPECT_GE(reprojectionIoU(result.mesh, result.hull.views()).min, 0.99);
}

/// The input with view 0's image shifted right by half its width: the object leaves the image.
HullInput withFirstViewCutByTheBorder(HullInput input) {
  const PinholeCamera& camera = input.cameras[0];
  Eigen::Matrix3d K = camera.K();
  const int shift = input.masks[0].cols / 2;
  K(0, 2) += shift;
  input.cameras[0] = PinholeCamera(K, camera.R(), camera.t());
  cv::Mat shifted = cv::Mat::zeros(input.masks[0].size(), CV_8UC1);
  input.masks[0](cv::Rect(0, 0, shift, shifted.rows))
      .copyTo(shifted(cv::Rect(shift, 0, shift, shifted.rows)));
  input.masks[0] = shifted;
  return input;
}

TEST(VisualHull, ViewsCarveOutsideTheirImageOnlyWhenAsked) {
  const HullInput full = test::sceneHullInput("sphere", 8);
  const HullInput cut = withFirstViewCutByTheBorder(full);
  HullInput without_first = full;
  without_first.names.erase(without_first.names.begin());
  without_first.cameras.erase(without_first.cameras.begin());
  without_first.masks.erase(without_first.masks.begin());
  const Box3d box = buildHull(full, depth(6)).box;  // one box for all three
  const double all_m3 = buildHull(full, depth(6), box).hull.stats().occupied_volume_m3;
  const double rest_m3 = buildHull(without_first, depth(6), box).hull.stats().occupied_volume_m3;
  HullConfig carving = depth(6);
  carving.carve_outside_image = true;
  const double kept_m3 = buildHull(cut, depth(6), box).hull.stats().occupied_volume_m3;
  const double carved_m3 = buildHull(cut, carving, box).hull.stats().occupied_volume_m3;
  // Kept: the half the cut view still sees carves as the whole view did; the other half is left
  // to the other views.
  EXPECT_GE(kept_m3, all_m3 * 0.999);
  EXPECT_LE(kept_m3, rest_m3 * 1.001);
  EXPECT_LT(carved_m3, 0.7 * all_m3);
}

TEST(VisualHull, ResetLeavesOneInCellAndNoViews) {
  HullResult result = buildHull(test::sceneHullInput("sphere", 6), depth(5));
  result.hull.reset();
  EXPECT_TRUE(result.hull.views().empty());
  const HullStats stats = result.hull.stats();
  EXPECT_EQ(stats.in_leaves, 1u);
  EXPECT_EQ(stats.surface_leaves + stats.out_leaves, 0u);
}

}  // namespace
}  // namespace sift_hull
