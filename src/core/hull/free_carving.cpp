// Free-space carving of VisualHull's octree: finest voxels known to be empty (lines of sight to
// surface points, src/core/refine) become out, with the closure and the surface cells around them
// that keep the result independent of the order of views and voxels and the mesh closed.

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "hull/octree_node.h"
#include "hull/voxel_key.h"
#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace {

using detail::inCube;
using detail::OctreeNode;

/// f_free at the corners of free voxels, in the silhouettes' units (pixels); the corners next to
/// them are held no lower than kWallField_px, so that marching cubes puts the cavity's wall a
/// quarter of a voxel beyond the free voxels (1 / (1 + 3) of the edge).
constexpr float kFreeField_px = 1.0f;
constexpr float kWallField_px = -3.0f;

/// The 26 neighbours' offsets.
const std::array<Eigen::Vector3i, 26>& neighbourOffsets() {
  static const std::array<Eigen::Vector3i, 26> offsets = [] {
    std::array<Eigen::Vector3i, 26> list;
    size_t n = 0;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx != 0 || dy != 0 || dz != 0) list[n++] = Eigen::Vector3i(dx, dy, dz);
        }
      }
    }
    return list;
  }();
  return offsets;
}

Eigen::Vector3i cornerOffset(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

/// Whether a grid point (a voxel corner, in voxels from the cube's corner) touches a free voxel.
bool cornerTouchesFree(const std::unordered_set<uint64_t>& free, const Eigen::Vector3i& corner,
                       int cells) {
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3i voxel = corner - cornerOffset(c);
    if (inCube(voxel, cells) && free.count(detail::voxelKey(voxel)) > 0) return true;
  }
  return false;
}

/// The finest leaf of a voxel, splitting in leaves on the way (their children are in, as they
/// are); nullptr when the voxel lies in an out cell.
OctreeNode* finestLeaf(OctreeNode* root, const Eigen::Vector3i& voxel, int depth) {
  OctreeNode* node = root;
  for (int level = 0; level < depth; ++level) {
    if (node->state == CellState::kOut) return nullptr;
    if (!node->children) node->children = std::make_unique<OctreeNode[]>(8);
    const int shift = depth - level - 1;
    const int child = ((voxel.x() >> shift) & 1) | (((voxel.y() >> shift) & 1) << 1) |
                      (((voxel.z() >> shift) & 1) << 2);
    node = &node->children[child];
  }
  return node->state == CellState::kOut ? nullptr : node;
}

}  // namespace

void VisualHull::carveFree(const std::vector<Eigen::Vector3i>& voxels) {
  const int cells = 1 << cube_.depth;
  std::vector<Eigen::Vector3i> added;
  for (const Eigen::Vector3i& voxel : voxels) {
    if (inCube(voxel, cells) && free_.insert(detail::voxelKey(voxel)).second)
      added.push_back(voxel);
  }
  // The closure: a voxel all of whose corners touch free voxels has f_free > 0 all over; it is
  // free too. Adding it changes no corner's state, so the closure needs one pass.
  const size_t given = added.size();
  for (size_t i = 0; i < given; ++i) {
    for (const Eigen::Vector3i& offset : neighbourOffsets()) {
      const Eigen::Vector3i voxel = added[i] + offset;
      if (!inCube(voxel, cells) || free_.count(detail::voxelKey(voxel)) > 0) continue;
      bool enclosed = true;
      for (int c = 0; c < 8 && enclosed; ++c) {
        enclosed = cornerTouchesFree(free_, voxel + cornerOffset(c), cells);
      }
      if (enclosed && free_.insert(detail::voxelKey(voxel)).second) added.push_back(voxel);
    }
  }
  applyFree(added);
}

void VisualHull::applyFree(const std::vector<Eigen::Vector3i>& voxels) {
  const int cells = 1 << cube_.depth;
  for (const Eigen::Vector3i& voxel : voxels) {
    OctreeNode* leaf = finestLeaf(root_.get(), voxel, cube_.depth);
    if (leaf != nullptr) leaf->state = CellState::kOut;
  }
  // Their in neighbours hold the cavity's wall: finest surface cells, for marching cubes.
  for (const Eigen::Vector3i& voxel : voxels) {
    for (const Eigen::Vector3i& offset : neighbourOffsets()) {
      const Eigen::Vector3i neighbour = voxel + offset;
      if (!inCube(neighbour, cells) || free_.count(detail::voxelKey(neighbour)) > 0) continue;
      OctreeNode* leaf = finestLeaf(root_.get(), neighbour, cube_.depth);
      if (leaf != nullptr) leaf->state = CellState::kSurface;
    }
  }
}

std::vector<Eigen::Vector3i> VisualHull::freeVoxels() const {
  std::vector<Eigen::Vector3i> voxels;
  voxels.reserve(free_.size());
  for (const uint64_t key : free_) voxels.push_back(detail::voxelOfKey(key));
  return voxels;
}

void VisualHull::addFreeField(const std::vector<Eigen::Vector3d>& points_W,
                              std::vector<float>* values) const {
  if (free_.empty()) return;
  const int cells = 1 << cube_.depth;
  const Eigen::Vector3d origin_W = cube_.origin_W();
  for (size_t i = 0; i < points_W.size(); ++i) {
    // Marching cubes samples the voxels' corners: grid points, up to rounding.
    const Eigen::Vector3d grid = (points_W[i] - origin_W) / cube_.resolution_m;
    const Eigen::Vector3i corner = grid.array().round().cast<int>();
    float& value = (*values)[i];
    if (cornerTouchesFree(free_, corner, cells)) {
      value = std::max(value, kFreeField_px);
      continue;
    }
    for (int axis = 0; axis < 3 && value < kWallField_px; ++axis) {
      for (const int step : {-1, 1}) {
        if (cornerTouchesFree(free_, corner + step * Eigen::Vector3i::Unit(axis), cells)) {
          value = kWallField_px;
          break;
        }
      }
    }
  }
}

std::vector<Eigen::Vector3i> VisualHull::hollowVoxels() const {
  std::vector<Eigen::Vector3i> hollow;
  if (free_.empty()) return hollow;
  const int cells = 1 << cube_.depth;
  // The finest surface cells with a corner on a free voxel, and their other corners.
  std::vector<Eigen::Vector3i> candidates;
  std::vector<Eigen::Vector3i> open_corners;  // corners not touching free voxels, per candidate
  std::vector<uint8_t> open_masks;
  for (const Eigen::Vector3i& voxel : surfaceCells().cells) {
    bool near_free = false;
    for (const Eigen::Vector3i& offset : neighbourOffsets()) {
      const Eigen::Vector3i other = voxel + offset;
      if (inCube(other, cells) && free_.count(detail::voxelKey(other)) > 0) {
        near_free = true;
        break;
      }
    }
    if (!near_free) continue;
    uint8_t open = 0;
    for (int c = 0; c < 8; ++c) {
      if (!cornerTouchesFree(free_, voxel + cornerOffset(c), cells)) {
        open |= static_cast<uint8_t>(1u << c);
        open_corners.push_back(voxel + cornerOffset(c));
      }
    }
    candidates.push_back(voxel);
    open_masks.push_back(open);
  }
  // f_iso at the open corners, sampled as mesh() samples them.
  std::vector<Eigen::Vector3d> points_W;
  points_W.reserve(open_corners.size());
  for (const Eigen::Vector3i& corner : open_corners) {
    points_W.push_back(cube_.origin_W() + corner.cast<double>() * cube_.resolution_m);
  }
  std::vector<float> values;
  sampleField(points_W, &values);
  size_t next = 0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    bool outside = true;
    for (int c = 0; c < 8; ++c) {
      if (open_masks[i] >> c & 1u) outside = values[next++] > 0.0f && outside;
    }
    if (outside) hollow.push_back(candidates[i]);
  }
  return hollow;
}

namespace {

/// The finest voxels of `cell` within [lo, hi] (inclusive), as two corners; false when none.
bool cellSpan(const HullCell& cell, int depth, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
              Eigen::Vector3i* first, Eigen::Vector3i* last) {
  const int scale = 1 << (depth - cell.depth);
  *first = (cell.index * scale).cwiseMax(lo);
  *last = ((cell.index + Eigen::Vector3i::Ones()) * scale - Eigen::Vector3i::Ones()).cwiseMin(hi);
  return (first->array() <= last->array()).all();
}

}  // namespace

std::vector<Eigen::Vector3i> occupiedVoxelsIn(const VisualHull& hull, const Box3d& box_W,
                                              size_t max_voxels) {
  const HullCube& cube = hull.cube();
  const int cells = 1 << cube.depth;
  const Eigen::Vector3d lo_f =
      ((box_W.min_W - cube.origin_W()) / cube.resolution_m).array().floor();
  const Eigen::Vector3d hi_f =
      ((box_W.max_W - cube.origin_W()) / cube.resolution_m).array().floor();
  const Eigen::Vector3d last(cells - 1, cells - 1, cells - 1);
  // Clamped in double first: a box far outside the cube must not overflow an int.
  const Eigen::Vector3i lo = lo_f.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(last).cast<int>();
  const Eigen::Vector3i hi = hi_f.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(last).cast<int>();
  std::vector<Eigen::Vector3i> voxels;
  if ((lo_f.array() > last.array()).any() || (hi_f.array() < 0.0).any()) return voxels;
  size_t count = 0;
  std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3i>> spans;
  hull.forEachLeaf([&](const HullCell& cell) {
    Eigen::Vector3i first, end;
    if (cell.state == CellState::kOut || !cellSpan(cell, cube.depth, lo, hi, &first, &end)) return;
    const Eigen::Vector3i extent = end - first + Eigen::Vector3i::Ones();
    count += static_cast<size_t>(extent.x()) * static_cast<size_t>(extent.y()) *
             static_cast<size_t>(extent.z());
    spans.emplace_back(first, end);
  });
  if (count > max_voxels) {
    throw std::invalid_argument("the box touches " + std::to_string(count) +
                                " occupied voxels, more than " + std::to_string(max_voxels) +
                                " cleared at once");
  }
  voxels.reserve(count);
  for (const auto& span : spans) {
    for (int z = span.first.z(); z <= span.second.z(); ++z) {
      for (int y = span.first.y(); y <= span.second.y(); ++y) {
        for (int x = span.first.x(); x <= span.second.x(); ++x) voxels.emplace_back(x, y, z);
      }
    }
  }
  return voxels;
}

}  // namespace sift_hull
