#pragma once
// Meshes, fields and cameras shared by the mesh tests of every layer (test_mesh, test_ply,
// test_mesh_render).

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
#include <utility>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/marching_cubes.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {
namespace test {

inline constexpr double kPi = 3.14159265358979323846;

using ScalarField = std::function<double(const Eigen::Vector3d&)>;

inline FieldSampler samplerOf(const ScalarField& field) {
  return [field](const std::vector<Eigen::Vector3d>& points_W, std::vector<float>* values) {
    values->resize(points_W.size());
    for (size_t i = 0; i < points_W.size(); ++i)
      (*values)[i] = static_cast<float>(field(points_W[i]));
  };
}

/// The cells of the grid over [low, low + count * edge] whose corners straddle zero under the
/// same rule (value >= 0 outside) and float precision marching cubes uses.
inline SurfaceCells straddlingCells(const ScalarField& field, const Eigen::Vector3d& low, int count,
                                    double edge) {
  const int points = count + 1;
  std::vector<bool> outside(static_cast<size_t>(points) * points * points);
  const auto at = [points](int i, int j, int k) {
    return (static_cast<size_t>(k) * points + j) * points + i;
  };
  for (int k = 0; k < points; ++k) {
    for (int j = 0; j < points; ++j) {
      for (int i = 0; i < points; ++i) {
        const Eigen::Vector3d p = low + edge * Eigen::Vector3d(i, j, k);
        outside[at(i, j, k)] = static_cast<float>(field(p)) >= 0.0f;
      }
    }
  }
  SurfaceCells cells;
  cells.origin_W = low;
  cells.cell_edge_m = edge;
  for (int k = 0; k < count; ++k) {
    for (int j = 0; j < count; ++j) {
      for (int i = 0; i < count; ++i) {
        int outside_corners = 0;
        for (int c = 0; c < 8; ++c)
          outside_corners += outside[at(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))];
        if (outside_corners > 0 && outside_corners < 8) cells.cells.emplace_back(i, j, k);
      }
    }
  }
  return cells;
}

/// V - E + F over the vertices faces use: 2 for a sphere, 0 for a torus.
inline long eulerCharacteristic(const TriangleMesh& mesh) {
  std::set<int> used_vertices;
  std::set<std::pair<int, int>> edges;
  for (const Eigen::Vector3i& face : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      used_vertices.insert(face[k]);
      edges.insert(std::minmax(face[k], face[(k + 1) % 3]));
    }
  }
  return static_cast<long>(used_vertices.size()) - static_cast<long>(edges.size()) +
         static_cast<long>(mesh.faces.size());
}

inline double smallestFaceArea(const TriangleMesh& mesh) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3i& face : mesh.faces) {
    const Eigen::Vector3d v0 = mesh.vertices_W[face[0]].cast<double>();
    const Eigen::Vector3d v1 = mesh.vertices_W[face[1]].cast<double>();
    const Eigen::Vector3d v2 = mesh.vertices_W[face[2]].cast<double>();
    smallest = std::min(smallest, 0.5 * (v1 - v0).cross(v2 - v0).norm());
  }
  return smallest;
}

inline const Eigen::Vector3d kSphereCentre(0.013, -0.021, 0.007);
inline constexpr double kSphereRadius = 1.0;
inline constexpr double kCellEdge = 0.05;

inline double sphereField(const Eigen::Vector3d& p) {
  return (p - kSphereCentre).norm() - kSphereRadius;
}

inline TriangleMesh sphereMesh() {
  const SurfaceCells cells =
      straddlingCells(sphereField, Eigen::Vector3d::Constant(-1.2),
                      static_cast<int>(std::lround(2.4 / kCellEdge)), kCellEdge);
  return marchingCubes(cells, samplerOf(sphereField));
}

/// A tetrahedron with outward faces.
inline TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices_W = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

/// Looks along +z from 4 units away at a point a little off the sphere's centre.
inline PinholeCamera sphereCamera() {
  Eigen::Matrix3d K;
  K << 500.0, 0.0, 161.5, 0.0, 520.0, 118.0, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.05, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d centre = kSphereCentre - 4.0 * R.row(2).transpose();
  return PinholeCamera::fromCentre(K, R, centre);
}

/// A camera at the origin looking along +z that maps (x, y, 1) to pixel (x, y).
inline PinholeCamera unitCamera() {
  return PinholeCamera(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
                       Eigen::Vector3d::Zero());
}

inline void expectWatertight(const TriangleMesh& mesh) {
  const MeshCheck check = checkMesh(mesh);
  EXPECT_TRUE(check.watertight);
  EXPECT_EQ(check.boundary_edges, 0u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
  EXPECT_EQ(check.misoriented_edges, 0u);
  EXPECT_EQ(check.degenerate_faces, 0u);
}

}  // namespace test
}  // namespace sift_hull
