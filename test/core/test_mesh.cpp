#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "common/mesh_fixtures.h"
#include "sift_hull/hull/marching_cubes.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {
namespace {

using namespace test;

TEST(MarchingCubesTest, SphereIsClosedOutwardAndClose) {
  const TriangleMesh mesh = sphereMesh();
  ASSERT_FALSE(mesh.faces.empty());
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  const double exact = 4.0 / 3.0 * kPi * std::pow(kSphereRadius, 3);
  const double volume = meshVolume(mesh);
  EXPECT_GT(volume, 0.0);
  EXPECT_NEAR(volume, exact, 0.01 * exact);
  // Linear interpolation of a distance field along an edge errs by at most edge^2 / (8 radius).
  const double tolerance = kCellEdge * kCellEdge / (4.0 * kSphereRadius);
  double worst = 0.0;
  for (const Eigen::Vector3f& vertex : mesh.vertices_W) {
    worst = std::max(worst, std::abs(sphereField(vertex.cast<double>())));
  }
  EXPECT_LT(worst, tolerance);
}

TEST(MarchingCubesTest, SamplesEachCornerOnceInOneCall) {
  SurfaceCells cells;
  cells.cell_edge_m = 0.5;
  for (int i = 0; i < 8; ++i) cells.cells.emplace_back(i & 1, (i >> 1) & 1, i >> 2);
  int calls = 0;
  std::set<std::tuple<double, double, double>> distinct;
  size_t points = 0;
  const FieldSampler counting = [&](const std::vector<Eigen::Vector3d>& points_W,
                                    std::vector<float>* values) {
    ++calls;
    points += points_W.size();
    for (const Eigen::Vector3d& p : points_W) distinct.emplace(p.x(), p.y(), p.z());
    values->clear();
    for (const Eigen::Vector3d& p : points_W)
      values->push_back(static_cast<float>((p - Eigen::Vector3d::Constant(0.5)).norm() - 0.3));
  };
  const TriangleMesh mesh = marchingCubes(cells, counting);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(points, 27u);
  EXPECT_EQ(distinct.size(), 27u);
  expectWatertight(mesh);
}

TEST(MarchingCubesTest, ShiftedAndRepeatedCellsGiveTheSameSurface) {
  SurfaceCells cells = straddlingCells(sphereField, Eigen::Vector3d::Constant(-1.2), 48, kCellEdge);
  const TriangleMesh reference = marchingCubes(cells, samplerOf(sphereField));
  // Negative indices with the origin moved to match, and every cell listed twice.
  const Eigen::Vector3i shift(-30, -31, -32);
  cells.origin_W -= kCellEdge * shift.cast<double>();
  for (Eigen::Vector3i& cell : cells.cells) cell += shift;
  cells.cells.insert(cells.cells.end(), cells.cells.begin(), cells.cells.end());
  const TriangleMesh shifted = marchingCubes(cells, samplerOf(sphereField));
  expectWatertight(shifted);
  EXPECT_EQ(shifted.faces.size(), reference.faces.size());
  EXPECT_NEAR(meshVolume(shifted), meshVolume(reference), 1e-5);
}

TEST(MarchingCubesTest, BoxIsWatertight) {
  const Eigen::Vector3d half(0.7, 0.5, 0.3), centre(0.02, -0.03, 0.01);
  const ScalarField box = [&](const Eigen::Vector3d& p) {
    return ((p - centre).cwiseAbs() - half).maxCoeff();
  };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(box, Eigen::Vector3d::Constant(-1.0), 40, kCellEdge), samplerOf(box));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  // Cells cut by the box's edges lose at most half a cell face of cross-section along them.
  const double edge_length = 4.0 * 2.0 * half.sum();
  EXPECT_NEAR(meshVolume(mesh), 8.0 * half.prod(), edge_length * kCellEdge * kCellEdge);
}

TEST(MarchingCubesTest, TorusIsWatertightWithGenusOne) {
  const ScalarField torus = [](const Eigen::Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - 1.0, p.z()) - 0.3;
  };
  const TriangleMesh mesh =
      marchingCubes(straddlingCells(torus, Eigen::Vector3d(-1.41, -1.42, -0.43), 57, kCellEdge),
                    samplerOf(torus));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 0);
  const double exact = 2.0 * kPi * kPi * 1.0 * 0.3 * 0.3;
  EXPECT_NEAR(meshVolume(mesh), exact, 0.02 * exact);
}

TEST(MarchingCubesTest, CornersExactlyOnTheSurfaceKeepItWatertight) {
  // Grid points (3,0,0), (2,2,1) etc. times 0.25 lie exactly on the sphere of radius 0.75.
  const ScalarField sphere = [](const Eigen::Vector3d& p) { return p.norm() - 0.75; };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(sphere, Eigen::Vector3d::Constant(-1.25), 10, 0.25), samplerOf(sphere));
  expectWatertight(mesh);
  EXPECT_EQ(eulerCharacteristic(mesh), 2);
  EXPECT_GT(meshVolume(mesh), 0.0);
  // Vertices stay off the zero corners, so no two of a face coincide.
  EXPECT_GT(smallestFaceArea(mesh), 0.0);
}

TEST(MarchingCubesTest, RandomFieldWithAmbiguousCellsIsWatertight) {
  constexpr int kPoints = 14;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<double> grid(kPoints * kPoints * kPoints);
  for (double& v : grid) v = value(rng);
  // Positive on the grid's border, so that the surface closes inside it.
  const ScalarField field = [&grid](const Eigen::Vector3d& p) {
    const Eigen::Vector3i index = p.array().round().cast<int>().matrix();
    if (index.minCoeff() <= 0 || index.maxCoeff() >= kPoints - 1) return 1.0;
    return grid[(index.z() * kPoints + index.y()) * kPoints + index.x()];
  };
  const TriangleMesh mesh = marchingCubes(
      straddlingCells(field, Eigen::Vector3d::Zero(), kPoints - 1, 1.0), samplerOf(field));
  ASSERT_GT(mesh.faces.size(), 1000u);
  expectWatertight(mesh);
  EXPECT_GT(meshVolume(mesh), 0.0);
}

TEST(MarchingCubesTest, EmptyCellListGivesEmptyMesh) {
  bool called = false;
  const TriangleMesh mesh = marchingCubes(
      SurfaceCells(),
      [&called](const std::vector<Eigen::Vector3d>&, std::vector<float>*) { called = true; });
  EXPECT_TRUE(mesh.vertices_W.empty());
  EXPECT_TRUE(mesh.faces.empty());
  EXPECT_FALSE(called);
}

TEST(MarchingCubesTest, RejectsAFieldReturningTheWrongCount) {
  SurfaceCells cells;
  cells.cells.emplace_back(0, 0, 0);
  EXPECT_THROW(marchingCubes(cells, [](const std::vector<Eigen::Vector3d>&,
                                       std::vector<float>* values) { values->assign(3, 1.0f); }),
               std::runtime_error);
  cells.cell_edge_m = 0.0;
  EXPECT_THROW(marchingCubes(cells, samplerOf(sphereField)), std::invalid_argument);
}

TEST(CheckMeshTest, EmptyMeshIsNotWatertight) {
  EXPECT_FALSE(checkMesh(TriangleMesh()).watertight);
}

TEST(CheckMeshTest, DetectsMissingFlippedDuplicatedAndDegenerateFaces) {
  expectWatertight(tetrahedron());

  TriangleMesh missing = tetrahedron();
  missing.faces.pop_back();
  EXPECT_FALSE(checkMesh(missing).watertight);
  EXPECT_EQ(checkMesh(missing).boundary_edges, 3u);

  TriangleMesh flipped = tetrahedron();
  std::swap(flipped.faces[0][1], flipped.faces[0][2]);
  EXPECT_FALSE(checkMesh(flipped).watertight);
  EXPECT_EQ(checkMesh(flipped).misoriented_edges, 3u);

  TriangleMesh duplicated = tetrahedron();
  duplicated.faces.push_back(duplicated.faces[0]);
  EXPECT_FALSE(checkMesh(duplicated).watertight);
  EXPECT_EQ(checkMesh(duplicated).non_manifold_edges, 3u);

  TriangleMesh degenerate = tetrahedron();
  degenerate.faces.emplace_back(1, 1, 2);
  EXPECT_FALSE(checkMesh(degenerate).watertight);
  EXPECT_EQ(checkMesh(degenerate).degenerate_faces, 1u);
  EXPECT_EQ(checkMesh(degenerate).boundary_edges, 0u);
}

TEST(MeshVolumeTest, TetrahedronHasSignedVolume) {
  TriangleMesh mesh = tetrahedron();
  EXPECT_NEAR(meshVolume(mesh), 1.0 / 6.0, 1e-12);
  for (Eigen::Vector3i& face : mesh.faces) std::swap(face[1], face[2]);
  EXPECT_NEAR(meshVolume(mesh), -1.0 / 6.0, 1e-12);
  EXPECT_EQ(meshVolume(TriangleMesh()), 0.0);
}

}  // namespace
}  // namespace sift_hull
