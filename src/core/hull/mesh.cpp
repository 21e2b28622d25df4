#include "sift_hull/hull/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

bool isIndexValid(int index, size_t vertex_count) {
  return index >= 0 && static_cast<size_t>(index) < vertex_count;
}

}  // namespace

bool areIndicesValid(const Eigen::Vector3i& face, size_t vertex_count) {
  return isIndexValid(face[0], vertex_count) && isIndexValid(face[1], vertex_count) &&
         isIndexValid(face[2], vertex_count);
}

void requireValidFaces(const TriangleMesh& mesh, const std::string& context) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!areIndicesValid(mesh.faces[f], mesh.vertices_W.size())) {
      throw std::invalid_argument(context + ": face " + std::to_string(f) +
                                  " references a vertex out of range");
    }
  }
}

namespace {

// ---------------------------------------------------------------------------------------------
// Topology

bool isDegenerate(const Eigen::Vector3i& face, size_t vertex_count) {
  const bool repeats = face[0] == face[1] || face[1] == face[2] || face[2] == face[0];
  return repeats || !areIndicesValid(face, vertex_count);
}

// A face's edge as seen from its smaller vertex.
struct EdgeEnd {
  int larger;
  bool ascending;  ///< the face runs from the smaller vertex to the larger
};

// Edge ends of the non-degenerate faces grouped by their smaller vertex: the group of vertex v is
// ends[starts[v]] up to ends[starts[v + 1]]. Groups are small, so this replaces sorting all edges.
struct EdgeGroups {
  std::vector<size_t> starts;
  std::vector<EdgeEnd> ends;
};

EdgeGroups groupEdgesBySmallerVertex(const TriangleMesh& mesh) {
  const size_t vertex_count = mesh.vertices_W.size();
  EdgeGroups groups;
  groups.starts.assign(vertex_count + 1, 0);
  for (const Eigen::Vector3i& face : mesh.faces) {
    if (isDegenerate(face, vertex_count)) continue;
    for (int k = 0; k < 3; ++k) ++groups.starts[std::min(face[k], face[(k + 1) % 3]) + 1];
  }
  std::partial_sum(groups.starts.begin(), groups.starts.end(), groups.starts.begin());
  groups.ends.resize(groups.starts.back());
  std::vector<size_t> next(groups.starts.begin(), groups.starts.end() - 1);
  for (const Eigen::Vector3i& face : mesh.faces) {
    if (isDegenerate(face, vertex_count)) continue;
    for (int k = 0; k < 3; ++k) {
      const int from = face[k], to = face[(k + 1) % 3];
      groups.ends[next[std::min(from, to)]++] = {std::max(from, to), from < to};
    }
  }
  return groups;
}

void classifyEdge(size_t face_count, size_t ascending_count, MeshCheck* check) {
  if (face_count == 1) {
    ++check->boundary_edges;
  } else if (face_count >= 3) {
    ++check->non_manifold_edges;
  } else if (ascending_count != 1) {
    ++check->misoriented_edges;
  }
}

void classifyGroup(std::vector<EdgeEnd>::iterator first, std::vector<EdgeEnd>::iterator last,
                   MeshCheck* check) {
  std::sort(first, last, [](const EdgeEnd& a, const EdgeEnd& b) { return a.larger < b.larger; });
  while (first != last) {
    size_t faces = 0, ascending = 0;
    const int larger = first->larger;
    for (; first != last && first->larger == larger; ++first) {
      ++faces;
      ascending += first->ascending ? 1 : 0;
    }
    classifyEdge(faces, ascending, check);
  }
}

}  // namespace

MeshCheck checkMesh(const TriangleMesh& mesh) {
  MeshCheck check;
  check.degenerate_faces = static_cast<size_t>(std::count_if(
      mesh.faces.begin(), mesh.faces.end(),
      [&mesh](const Eigen::Vector3i& face) { return isDegenerate(face, mesh.vertices_W.size()); }));
  EdgeGroups groups = groupEdgesBySmallerVertex(mesh);
  for (size_t vertex = 0; vertex < mesh.vertices_W.size(); ++vertex) {
    classifyGroup(groups.ends.begin() + groups.starts[vertex],
                  groups.ends.begin() + groups.starts[vertex + 1], &check);
  }
  check.watertight = !mesh.faces.empty() && check.boundary_edges == 0 &&
                     check.non_manifold_edges == 0 && check.misoriented_edges == 0 &&
                     check.degenerate_faces == 0;
  return check;
}

double meshVolume(const TriangleMesh& mesh) {
  requireValidFaces(mesh, "meshVolume");
  double six_volume = 0.0;
  for (const Eigen::Vector3i& face : mesh.faces) {
    const Eigen::Vector3d v0 = mesh.vertices_W[face[0]].cast<double>();
    const Eigen::Vector3d v1 = mesh.vertices_W[face[1]].cast<double>();
    const Eigen::Vector3d v2 = mesh.vertices_W[face[2]].cast<double>();
    six_volume += v0.dot(v1.cross(v2));
  }
  return six_volume / 6.0;
}

}  // namespace sift_hull
