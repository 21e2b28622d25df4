#include <vtkMarchingCubesTriangleCases.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "sift_hull/mesh.h"

namespace sift_hull {
namespace {

// VTK's case table numbers the cube corners in hexahedron order and its edges as below; a case bit
// is set where the scalar is >= the iso value.
constexpr int kCornerOffsets[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
// Each edge as (lower corner, upper corner), with the axis it runs along.
constexpr int kEdgeCorners[12][2] = {{0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6},
                                     {7, 6}, {4, 7}, {0, 4}, {1, 5}, {3, 7}, {2, 6}};
constexpr int kEdgeAxis[12] = {0, 1, 0, 1, 0, 1, 0, 1, 2, 2, 2, 2};

// A vertex is kept at least this fraction of the edge away from its corners, so that a corner value
// of exactly zero does not make vertices of neighbouring edges coincide.
constexpr double kMinEdgeFraction = 1e-3;

constexpr int kKeyBits = 21;
constexpr int64_t kKeyRange = int64_t{1} << kKeyBits;

// Packs grid point indices relative to the lowest corner into 63 bits, i in the lowest bits, so
// that the point one step along +i has the next key.
class CornerKeys {
 public:
  explicit CornerKeys(const std::vector<Eigen::Vector3i>& cells) {
    Eigen::Array<int64_t, 3, 1> lowest =
        Eigen::Array<int64_t, 3, 1>::Constant(std::numeric_limits<int64_t>::max());
    Eigen::Array<int64_t, 3, 1> highest =
        Eigen::Array<int64_t, 3, 1>::Constant(std::numeric_limits<int64_t>::min());
    for (const Eigen::Vector3i& cell : cells) {
      lowest = lowest.min(cell.cast<int64_t>().array());
      highest = highest.max(cell.cast<int64_t>().array() + 1);
    }
    if ((highest - lowest >= kKeyRange).any()) {
      throw std::invalid_argument("marchingCubes: the cells span more than 2^" +
                                  std::to_string(kKeyBits) + " grid points along an axis");
    }
    lowest_ = lowest;
  }

  uint64_t key(const Eigen::Vector3i& index) const {
    const Eigen::Array<int64_t, 3, 1> relative = index.cast<int64_t>().array() - lowest_;
    return static_cast<uint64_t>(relative.x()) | (static_cast<uint64_t>(relative.y()) << kKeyBits) |
           (static_cast<uint64_t>(relative.z()) << (2 * kKeyBits));
  }

  Eigen::Vector3i index(uint64_t key) const {
    const uint64_t mask = static_cast<uint64_t>(kKeyRange - 1);
    const Eigen::Array<int64_t, 3, 1> relative(static_cast<int64_t>(key & mask),
                                               static_cast<int64_t>((key >> kKeyBits) & mask),
                                               static_cast<int64_t>(key >> (2 * kKeyBits)));
    return (relative + lowest_).cast<int>().matrix();
  }

 private:
  Eigen::Array<int64_t, 3, 1> lowest_;
};

Eigen::Vector3i cornerOf(const Eigen::Vector3i& cell, int corner) {
  return cell + Eigen::Vector3i(kCornerOffsets[corner][0], kCornerOffsets[corner][1],
                                kCornerOffsets[corner][2]);
}

// Packing is linear, so a corner's key is its cell's key plus a per-corner offset.
uint64_t cornerKeyOffset(int corner) {
  return static_cast<uint64_t>(kCornerOffsets[corner][0]) |
         (static_cast<uint64_t>(kCornerOffsets[corner][1]) << kKeyBits) |
         (static_cast<uint64_t>(kCornerOffsets[corner][2]) << (2 * kKeyBits));
}

std::vector<uint64_t> sortedCellKeys(const std::vector<Eigen::Vector3i>& cells,
                                     const CornerKeys& keys) {
  std::vector<uint64_t> cell_keys;
  cell_keys.reserve(cells.size());
  for (const Eigen::Vector3i& cell : cells) cell_keys.push_back(keys.key(cell));
  std::sort(cell_keys.begin(), cell_keys.end());
  cell_keys.erase(std::unique(cell_keys.begin(), cell_keys.end()), cell_keys.end());
  return cell_keys;
}

// The sorted union of sorted keys and the same keys shifted by `offset`.
std::vector<uint64_t> unionWithShifted(const std::vector<uint64_t>& keys, uint64_t offset) {
  std::vector<uint64_t> merged;
  merged.reserve(2 * keys.size());
  size_t plain = 0, shifted = 0;
  while (plain < keys.size() || shifted < keys.size()) {
    const bool take_plain =
        shifted == keys.size() || (plain < keys.size() && keys[plain] <= keys[shifted] + offset);
    const uint64_t key = take_plain ? keys[plain++] : keys[shifted++] + offset;
    if (merged.empty() || merged.back() != key) merged.push_back(key);
  }
  return merged;
}

// The corners of the cells are the cells shifted by {0, 1} along each axis in turn; three merges
// of sorted lists keep the keys sorted and need far less memory than sorting eight copies.
std::vector<uint64_t> distinctCornerKeys(const std::vector<uint64_t>& cell_keys) {
  std::vector<uint64_t> keys = cell_keys;
  for (int axis = 0; axis < 3; ++axis) {
    keys = unionWithShifted(keys, uint64_t{1} << (axis * kKeyBits));
  }
  return keys;
}

// Samples in chunks, so that the points never all exist at once.
std::vector<float> sampleCorners(const SurfaceCells& cells, const CornerKeys& keys,
                                 const std::vector<uint64_t>& corner_keys,
                                 const FieldSampler& field) {
  constexpr size_t kChunk = size_t{1} << 16;
  std::vector<float> values;
  values.reserve(corner_keys.size());
  std::vector<Eigen::Vector3d> points_W;
  std::vector<float> chunk_values;
  for (size_t begin = 0; begin < corner_keys.size(); begin += kChunk) {
    const size_t end = std::min(corner_keys.size(), begin + kChunk);
    points_W.clear();
    for (size_t i = begin; i < end; ++i) {
      points_W.push_back(cells.origin_W +
                         cells.cell_edge_m * keys.index(corner_keys[i]).cast<double>());
    }
    field(points_W, &chunk_values);
    if (chunk_values.size() != points_W.size()) {
      throw std::runtime_error("marchingCubes: the field returned " +
                               std::to_string(chunk_values.size()) + " values for " +
                               std::to_string(points_W.size()) + " points");
    }
    values.insert(values.end(), chunk_values.begin(), chunk_values.end());
  }
  return values;
}

// Fraction of the way from the lower to the upper corner at which the field crosses zero.
double zeroCrossing(float lower_value, float upper_value) {
  const double difference = static_cast<double>(lower_value) - upper_value;
  double fraction = difference == 0.0 ? 0.5 : lower_value / difference;
  if (!std::isfinite(fraction)) fraction = 0.5;
  return std::clamp(fraction, kMinEdgeFraction, 1.0 - kMinEdgeFraction);
}

class Polygoniser {
 public:
  Polygoniser(const SurfaceCells& cells, const FieldSampler& field)
      : cells_(cells),
        keys_(cells.cells),
        cell_keys_(sortedCellKeys(cells.cells, keys_)),
        corner_keys_(distinctCornerKeys(cell_keys_)),
        values_(sampleCorners(cells, keys_, corner_keys_, field)),
        edge_vertices_(3 * corner_keys_.size(), -1) {
    mesh_.vertices_W.reserve(cell_keys_.size());
    mesh_.faces.reserve(2 * cell_keys_.size());
  }

  // Visits the cells in key order, so each corner's key only grows from one cell to the next and
  // its id is found by advancing a cursor through the sorted corner keys.
  TriangleMesh run() {
    // Corners 0, 3, 4, 7 start the runs along +i; the other corners are the next keys.
    constexpr std::array<int, 4> kRunStarts = {0, 3, 4, 7};
    std::array<size_t, 4> cursors = {0, 0, 0, 0};
    for (uint64_t cell_key : cell_keys_) {
      for (int run = 0; run < 4; ++run) {
        const uint64_t target = cell_key + cornerKeyOffset(kRunStarts[run]);
        while (corner_keys_[cursors[run]] < target) ++cursors[run];
      }
      const std::array<int, 8> ids = cornerIds(cursors);
      polygoniseCell(keys_.index(cell_key), ids);
    }
    return std::move(mesh_);
  }

 private:
  // Corner ids in VTK order from the ids of corners 0, 3, 4 and 7.
  static std::array<int, 8> cornerIds(const std::array<size_t, 4>& run_starts) {
    const int base = static_cast<int>(run_starts[0]);
    const int up_j = static_cast<int>(run_starts[1]);
    const int up_k = static_cast<int>(run_starts[2]);
    const int up_jk = static_cast<int>(run_starts[3]);
    return {base, base + 1, up_j + 1, up_j, up_k, up_k + 1, up_jk + 1, up_jk};
  }

  int vertexOnEdge(const Eigen::Vector3i& cell, const std::array<int, 8>& ids, int edge) {
    const int lower = kEdgeCorners[edge][0];
    const int axis = kEdgeAxis[edge];
    int& vertex = edge_vertices_[3 * static_cast<size_t>(ids[lower]) + axis];
    if (vertex >= 0) return vertex;
    Eigen::Vector3d grid_point = cornerOf(cell, lower).cast<double>();
    grid_point[axis] += zeroCrossing(values_[ids[lower]], values_[ids[kEdgeCorners[edge][1]]]);
    vertex = static_cast<int>(mesh_.vertices_W.size());
    mesh_.vertices_W.push_back((cells_.origin_W + cells_.cell_edge_m * grid_point).cast<float>());
    return vertex;
  }

  void polygoniseCell(const Eigen::Vector3i& cell, const std::array<int, 8>& ids) {
    int case_index = 0;
    for (int corner = 0; corner < 8; ++corner) {
      if (values_[ids[corner]] >= 0.0f) case_index |= 1 << corner;
    }
    const int* edges = vtkMarchingCubesTriangleCases::GetCases()[case_index].edges;
    for (; edges[0] >= 0; edges += 3) {
      // The table's triangles face the corners whose bit is clear, here the inside; outward
      // normals need the reverse order.
      const int first = vertexOnEdge(cell, ids, edges[0]);
      const int second = vertexOnEdge(cell, ids, edges[1]);
      const int third = vertexOnEdge(cell, ids, edges[2]);
      mesh_.faces.emplace_back(first, third, second);
    }
  }

  const SurfaceCells& cells_;
  CornerKeys keys_;
  std::vector<uint64_t> cell_keys_;  ///< sorted, each cell once
  std::vector<uint64_t> corner_keys_;
  std::vector<float> values_;
  std::vector<int> edge_vertices_;  ///< vertex per (lower corner id, axis), -1 if none yet
  TriangleMesh mesh_;
};

}  // namespace

TriangleMesh marchingCubes(const SurfaceCells& cells, const FieldSampler& field) {
  if (!(cells.cell_edge_m > 0.0 && std::isfinite(cells.cell_edge_m))) {
    throw std::invalid_argument("marchingCubes: cell_edge_m must be positive and finite");
  }
  if (!cells.origin_W.allFinite()) {
    throw std::invalid_argument("marchingCubes: origin_W must be finite");
  }
  if (cells.cells.empty()) return {};
  return Polygoniser(cells, field).run();
}

}  // namespace sift_hull
