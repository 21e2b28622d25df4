#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sift_hull {

/// A triangle mesh in world coordinates; faces are counter-clockwise seen from outside, so their
/// normals (v1 - v0) x (v2 - v0) point out of the solid.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices_W;
  std::vector<Eigen::Vector3i> faces;
  /// Empty, or each vertex's colour (red, green, blue), as the photographs show it.
  std::vector<std::array<uint8_t, 3>> colours_rgb;
};

/// Topology of a mesh. Watertight: every edge has exactly two faces, which traverse it in opposite
/// directions, and no face is degenerate (repeated vertex index).
struct MeshCheck {
  bool watertight = false;
  size_t boundary_edges = 0;      ///< edges with one face
  size_t non_manifold_edges = 0;  ///< edges with three faces or more
  size_t misoriented_edges = 0;   ///< edges whose two faces traverse them the same way
  size_t degenerate_faces = 0;
};
MeshCheck checkMesh(const TriangleMesh& mesh);

/// Signed volume enclosed (positive for outward faces), in cubic world units.
double meshVolume(const TriangleMesh& mesh);

/// True when the face's three vertex indices are in [0, vertex_count).
bool areIndicesValid(const Eigen::Vector3i& face, size_t vertex_count);

/// Throws std::invalid_argument "CONTEXT: face F references a vertex out of range".
void requireValidFaces(const TriangleMesh& mesh, const std::string& context);

}  // namespace sift_hull
