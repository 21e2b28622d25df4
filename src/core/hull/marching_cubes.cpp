#include "sift_hull/hull/marching_cubes.h"

#include <vtkMarchingCubesTriangleCases.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

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

// Least-significant-digit radix sort, 16 bits a pass, skipping digits all keys share.
void radixSort(std::vector<uint64_t>* keys) {
  std::vector<uint64_t> buffer(keys->size());
  for (int shift = 0; shift < 64; shift += 16) {
    std::array<size_t, (1 << 16) + 1> starts{};
    for (uint64_t key : *keys) ++starts[((key >> shift) & 0xffff) + 1];
    if (std::count(starts.begin(), starts.end(), keys->size()) == 1) continue;
    for (size_t digit = 1; digit < starts.size(); ++digit) starts[digit] += starts[digit - 1];
    for (uint64_t key : *keys) buffer[starts[(key >> shift) & 0xffff]++] = key;
    keys->swap(buffer);
  }
}

std::vector<uint64_t> sortedCellKeys(const std::vector<Eigen::Vector3i>& cells,
                                     const CornerKeys& keys) {
  std::vector<uint64_t> cell_keys;
  cell_keys.reserve(cells.size());
  for (const Eigen::Vector3i& cell : cells) cell_keys.push_back(keys.key(cell));
  radixSort(&cell_keys);
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
std::vector<uint64_t> distinctCornerKeys(const uint64_t* first_cell, const uint64_t* last_cell) {
  std::vector<uint64_t> keys(first_cell, last_cell);
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

int zOfKey(uint64_t key) { return static_cast<int>(key >> (2 * kKeyBits)); }

/// Vertices on the x and y edges of one z plane, by 2 * corner key + axis: what one slab of cells
/// hands on to the next, which shares that plane.
using PlaneVertices = std::unordered_map<uint64_t, int>;

/// Marching cubes over one slab of cells (whole z layers), appending to a mesh. Working in slabs
/// keeps the corner arrays small.
class SlabPolygoniser {
 public:
  SlabPolygoniser(const SurfaceCells& cells, const CornerKeys& keys, const uint64_t* first_cell,
                  const uint64_t* last_cell, const FieldSampler& field, TriangleMesh* mesh)
      : cells_(cells),
        keys_(keys),
        first_cell_(first_cell),
        last_cell_(last_cell),
        corner_keys_(distinctCornerKeys(first_cell, last_cell)),
        values_(sampleCorners(cells, keys, corner_keys_, field)),
        edge_vertices_(3 * corner_keys_.size(), -1),
        mesh_(mesh) {}

  // Visits the cells in key order, so each corner's key only grows from one cell to the next and
  // its id is found by advancing a cursor through the sorted corner keys. Returns the vertices on
  // the slab's top plane.
  PlaneVertices run(const PlaneVertices& bottom_plane) {
    reuse(bottom_plane);
    // Corners 0, 3, 4, 7 start the runs along +i; the other corners are the next keys.
    constexpr std::array<int, 4> kRunStarts = {0, 3, 4, 7};
    std::array<size_t, 4> cursors = {0, 0, 0, 0};
    for (const uint64_t* cell_key = first_cell_; cell_key != last_cell_; ++cell_key) {
      for (int run = 0; run < 4; ++run) {
        const uint64_t target = *cell_key + cornerKeyOffset(kRunStarts[run]);
        while (corner_keys_[cursors[run]] < target) ++cursors[run];
      }
      polygoniseCell(keys_.index(*cell_key), cornerIds(cursors));
    }
    return topPlane();
  }

 private:
  /// Vertex slots of the bottom plane's edges that the slab below already filled.
  void reuse(const PlaneVertices& bottom_plane) {
    if (bottom_plane.empty()) return;
    const int bottom = zOfKey(corner_keys_.front());
    for (size_t id = 0; id < corner_keys_.size() && zOfKey(corner_keys_[id]) == bottom; ++id) {
      for (int axis = 0; axis < 2; ++axis) {
        const auto found = bottom_plane.find(2 * corner_keys_[id] + axis);
        if (found != bottom_plane.end()) edge_vertices_[3 * id + axis] = found->second;
      }
    }
  }

  PlaneVertices topPlane() const {
    PlaneVertices plane;
    const int top = zOfKey(corner_keys_.back());
    for (size_t id = corner_keys_.size(); id-- > 0 && zOfKey(corner_keys_[id]) == top;) {
      for (int axis = 0; axis < 2; ++axis) {
        const int vertex = edge_vertices_[3 * id + axis];
        if (vertex >= 0) plane.emplace(2 * corner_keys_[id] + axis, vertex);
      }
    }
    return plane;
  }

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
    vertex = static_cast<int>(mesh_->vertices_W.size());
    mesh_->vertices_W.push_back((cells_.origin_W + cells_.cell_edge_m * grid_point).cast<float>());
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
      mesh_->faces.emplace_back(first, third, second);
    }
  }

  const SurfaceCells& cells_;
  const CornerKeys& keys_;
  const uint64_t* first_cell_;
  const uint64_t* last_cell_;
  std::vector<uint64_t> corner_keys_;
  std::vector<float> values_;
  std::vector<int> edge_vertices_;  ///< vertex per (lower corner id, axis), -1 if none yet
  TriangleMesh* mesh_;
};

/// About this many cells to a slab, rounded up to whole z layers.
constexpr size_t kSlabCells = size_t{1} << 16;

/// End of the slab that starts at `first`: whole z layers holding about kSlabCells cells.
const uint64_t* slabEnd(const uint64_t* first, const uint64_t* last) {
  if (static_cast<size_t>(last - first) <= kSlabCells) return last;
  const int layer = zOfKey(first[kSlabCells - 1]);
  return std::find_if(first + kSlabCells, last,
                      [layer](uint64_t key) { return zOfKey(key) != layer; });
}

}  // namespace

TriangleMesh marchingCubes(SurfaceCells cells, const FieldSampler& field) {
  if (!(cells.cell_edge_m > 0.0 && std::isfinite(cells.cell_edge_m))) {
    throw std::invalid_argument("marchingCubes: cell_edge_m must be positive and finite");
  }
  if (!cells.origin_W.allFinite()) {
    throw std::invalid_argument("marchingCubes: origin_W must be finite");
  }
  if (cells.cells.empty()) return {};
  const CornerKeys keys(cells.cells);
  const std::vector<uint64_t> cell_keys = sortedCellKeys(cells.cells, keys);
  cells.cells = {};  // only the keys are needed from here on
  TriangleMesh mesh;
  // Typical surfaces give about one vertex per two cells and one face per cell.
  mesh.vertices_W.reserve(cell_keys.size() / 2);
  mesh.faces.reserve(cell_keys.size());
  PlaneVertices plane;
  const uint64_t* last = cell_keys.data() + cell_keys.size();
  for (const uint64_t* first = cell_keys.data(); first != last;) {
    const uint64_t* end = slabEnd(first, last);
    plane = SlabPolygoniser(cells, keys, first, end, field, &mesh).run(plane);
    first = end;
  }
  return mesh;
}

}  // namespace sift_hull
