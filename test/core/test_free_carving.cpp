// VisualHull::carveFree: free voxels leave the hull exactly, in any order of views and voxels, and
// the mesh closes around the cavity they make.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "common/test_data.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace {

HullConfig depth(int max_depth) {
  HullConfig config;
  config.max_depth = max_depth;
  return config;
}

std::vector<HullCell> leavesOf(const VisualHull& hull) {
  std::vector<HullCell> leaves;
  hull.forEachLeaf([&](const HullCell& cell) { leaves.push_back(cell); });
  return leaves;
}

void expectSameLeaves(const VisualHull& actual_hull, const VisualHull& expected_hull) {
  const std::vector<HullCell> expected = leavesOf(expected_hull), actual = leavesOf(actual_hull);
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < actual.size(); ++i) {
    ASSERT_EQ(actual[i].index, expected[i].index) << i;
    ASSERT_EQ(actual[i].depth, expected[i].depth) << i;
    ASSERT_EQ(actual[i].state, expected[i].state) << i;
    if (actual[i].state != CellState::kOut) {
      ASSERT_EQ(actual[i].centre_value, expected[i].centre_value) << i;
    }
  }
}

/// A ball of finest voxels about the cube's centre, radius in voxels, and a tunnel from it
/// along +x: a cavity no silhouette sees.
std::vector<Eigen::Vector3i> cavity(const VisualHull& hull, double radius) {
  const int cells = 1 << hull.cube().depth;
  const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5 * cells);
  std::vector<Eigen::Vector3i> voxels;
  for (int z = 0; z < cells; ++z) {
    for (int y = 0; y < cells; ++y) {
      for (int x = 0; x < cells; ++x) {
        const Eigen::Vector3d c = Eigen::Vector3d(x, y, z).array() + 0.5;
        const bool ball = (c - centre).norm() < radius;
        const bool tunnel = x > centre.x() && x < centre.x() + 2 * radius &&
                            std::abs(c.y() - centre.y()) < 1.0 &&
                            std::abs(c.z() - centre.z()) < 1.0;
        if (ball || tunnel) voxels.emplace_back(x, y, z);
      }
    }
  }
  return voxels;
}

class FreeCarving : public ::testing::Test {
 protected:
  void SetUp() override {
    const HullInput input = test::sceneHullInput("sphere", 8, "ring");
    views_ = makeHullViews(input.names, input.cameras, input.masks, depth(6));
    box_ = boundingBoxOf(views_);
  }
  std::vector<HullView> views_;
  Box3d box_;
};

TEST_F(FreeCarving, TheCavityLeavesTheHullExactlyAndTheMeshClosesAroundIt) {
  VisualHull hull(box_, depth(6));
  hull.addViews(views_);
  const double before_m3 = hull.stats().occupied_volume_m3;
  const std::vector<Eigen::Vector3i> voxels = cavity(hull, 6.0);
  for (const Eigen::Vector3i& v : voxels) {
    ASSERT_EQ(hull.leafAt(hull.cube().origin_W() +
                          (v.cast<double>().array() + 0.5).matrix() * hull.cube().resolution_m)
                  .state,
              CellState::kIn);
  }
  hull.carveFree(voxels);
  EXPECT_EQ(hull.freeVoxelCount(), voxels.size());  // a ball and a tunnel need no closure
  const double voxel_m3 = std::pow(hull.cube().resolution_m, 3);
  EXPECT_NEAR(hull.stats().occupied_volume_m3, before_m3 - voxels.size() * voxel_m3,
              1e-9 * before_m3);
  for (const Eigen::Vector3i& v : voxels) {
    const Eigen::Vector3d centre =
        hull.cube().origin_W() +
        (v.cast<double>().array() + 0.5).matrix() * hull.cube().resolution_m;
    EXPECT_EQ(hull.leafAt(centre).state, CellState::kOut);
  }
  // The OctoMap holds the cavity as free space; its compact writer agrees byte for byte.
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(hull);
  for (const Eigen::Vector3i& v : {voxels.front(), voxels.back()}) {
    const Eigen::Vector3d c = hull.cube().origin_W() +
                              (v.cast<double>().array() + 0.5).matrix() * hull.cube().resolution_m;
    const octomap::OcTreeNode* node = tree->search(c.x(), c.y(), c.z());
    ASSERT_NE(node, nullptr);
    EXPECT_FALSE(tree->isNodeOccupied(node));
  }
  std::stringstream reference;
  writeOctomapBinaryData(*tree, reference);
  EXPECT_TRUE(compactOctomap(hull).binary_data == reference.str());
  const TriangleMesh mesh = hull.mesh();
  const MeshCheck check = checkMesh(mesh);
  EXPECT_TRUE(check.watertight) << check.boundary_edges << " boundary edges";
  // The mesh holds the cavity: the free voxels grown by a quarter of a voxel (the ball's volume
  // by (6.25 / 6)^3, the thin tunnel's by (2.5 / 2)^2).
  VisualHull plain(box_, depth(6));
  plain.addViews(views_);
  const double removed_m3 = meshVolume(plain.mesh()) - meshVolume(mesh);
  EXPECT_GT(removed_m3, voxels.size() * voxel_m3);
  EXPECT_LT(removed_m3, 1.4 * voxels.size() * voxel_m3);
}

TEST_F(FreeCarving, AnyOrderOfViewsAndVoxelsGivesTheSameTree) {
  VisualHull reference(box_, depth(6));
  reference.addViews(views_);
  std::vector<Eigen::Vector3i> voxels = cavity(reference, 5.0);
  // A few scattered voxels too, some in cells the views carve (those change nothing).
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> any(0, (1 << 6) - 1);
  for (int i = 0; i < 300; ++i) voxels.emplace_back(any(rng), any(rng), any(rng));
  reference.carveFree(voxels);

  VisualHull carved_first(box_, depth(6));
  std::vector<Eigen::Vector3i> shuffled = voxels;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const size_t half = shuffled.size() / 2;
  carved_first.carveFree({shuffled.begin(), shuffled.begin() + half});
  carved_first.addViews({views_.begin(), views_.begin() + 3});
  carved_first.carveFree({shuffled.begin() + half, shuffled.end()});
  carved_first.carveFree(voxels);  // again: nothing changes
  carved_first.addViews({views_.begin() + 3, views_.end()});
  expectSameLeaves(carved_first, reference);
  EXPECT_EQ(carved_first.freeVoxelCount(), reference.freeVoxelCount());

  // Dropping the last view and adding it again keeps the free voxels.
  carved_first.dropLastView();
  carved_first.addView(views_.back());
  expectSameLeaves(carved_first, reference);
  EXPECT_TRUE(checkMesh(carved_first.mesh()).watertight);
}

TEST_F(FreeCarving, SurfaceCellsTheMeshLeavesEmptyAreFreeInTheMaps) {
  VisualHull hull(box_, depth(6));
  hull.addViews(views_);
  EXPECT_TRUE(hull.hollowVoxels().empty());  // no free voxels: nothing to decide
  // The top of the ball cut off: the walls beside the cut, where it meets the silhouettes'
  // surface, have corners outside by f_iso and corners on free voxels.
  const HullCube& cube = hull.cube();
  Box3d top = box_;
  top.min_W.z() = box_.max_W.z() - 0.3 * (box_.max_W.z() - box_.min_W.z());
  hull.carveFree(occupiedVoxelsIn(hull, top, 1u << 20));
  const std::vector<Eigen::Vector3i> hollow = hull.hollowVoxels();
  ASSERT_FALSE(hollow.empty());
  const TriangleMesh mesh = hull.mesh();
  const std::unique_ptr<octomap::OcTree> tree = toOctomap(hull);
  for (const Eigen::Vector3i& voxel : hollow) {
    // A finest surface cell: occupied in the tree of the silhouettes, free in the maps now.
    const Eigen::Vector3d lo = cube.origin_W() + voxel.cast<double>() * cube.resolution_m;
    const HullCell cell = hull.leafAt(lo + Eigen::Vector3d::Constant(0.5 * cube.resolution_m));
    ASSERT_EQ(cell.state, CellState::kSurface);
    ASSERT_EQ(cell.depth, cube.depth);
    const Eigen::Vector3d c = lo + Eigen::Vector3d::Constant(0.5 * cube.resolution_m);
    const octomap::OcTreeNode* node = tree->search(c.x(), c.y(), c.z());
    ASSERT_NE(node, nullptr);
    EXPECT_FALSE(tree->isNodeOccupied(node));
    // ... and the mesh has no vertex on its edges: marching cubes found no surface in it.
    const double inset = 1e-6 * cube.resolution_m;
    for (const Eigen::Vector3f& vertex_f : mesh.vertices_W) {
      const Eigen::Vector3d vertex = vertex_f.cast<double>();
      const bool within = ((vertex - lo).array() > inset).all() &&
                          ((vertex - lo).array() < cube.resolution_m - inset).all();
      ASSERT_FALSE(within) << "a mesh vertex inside hollow voxel " << voxel.transpose();
    }
  }
  // The occupied blocks leave them out; the compact writer agrees with toOctomap byte for byte.
  size_t occupied_voxels = 0;
  for (const VoxelBlock& block : occupiedBlocks(hull)) {
    occupied_voxels +=
        static_cast<size_t>(block.edge_voxels) * block.edge_voxels * block.edge_voxels;
  }
  std::vector<VoxelBlock> occupied, carved;
  leafBlocks(hull, &occupied, &carved);
  EXPECT_EQ(occupied.size(), occupiedBlocks(hull).size());
  size_t all_voxels = occupied_voxels;
  for (const VoxelBlock& block : carved) {
    all_voxels += static_cast<size_t>(block.edge_voxels) * block.edge_voxels * block.edge_voxels;
  }
  EXPECT_EQ(all_voxels, size_t{1} << (3 * cube.depth));  // every voxel once
  std::stringstream reference;
  writeOctomapBinaryData(*tree, reference);
  EXPECT_TRUE(compactOctomap(hull).binary_data == reference.str());
}

TEST_F(FreeCarving, AVoxelEnclosedByFreeOnesIsFreeAndResetForgetsThemAll) {
  VisualHull hull(box_, depth(6));
  hull.addViews(views_);
  // A 3x3x3 block about the centre without its middle voxel: the middle is closed in.
  std::vector<Eigen::Vector3i> shell;
  for (int c = 0; c < 27; ++c) {
    if (c != 13) shell.emplace_back(31 + c % 3, 31 + c / 3 % 3, 31 + c / 9);
  }
  hull.carveFree(shell);
  EXPECT_EQ(hull.freeVoxelCount(), 27u);
  const Eigen::Vector3d middle =
      hull.cube().origin_W() + Eigen::Vector3d::Constant(32.5 * hull.cube().resolution_m);
  EXPECT_EQ(hull.leafAt(middle).state, CellState::kOut);
  hull.carveFree({Eigen::Vector3i(-1, 0, 0), Eigen::Vector3i(0, 64, 0)});  // outside: ignored
  EXPECT_EQ(hull.freeVoxelCount(), 27u);
  hull.reset();
  EXPECT_EQ(hull.freeVoxelCount(), 0u);
}

}  // namespace
}  // namespace sift_hull
