// The hull's OctoMap as toOctomap builds and prunes it, written straight from the hull's octree:
// each OctoMap node's state over its voxels is read off the hull's cells, so that no OctoMap node
// is allocated. The hull's cube lies anywhere on the voxel grid, so one OctoMap node may straddle
// up to eight hull cells of its size.

#include <cstdint>
#include <string>
#include <vector>

#include "hull/octomap_keys.h"
#include "hull/octree_node.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace {

using detail::OctreeNode;
using namespace octomap_keys;

/// OctoMap's child codes in its binary stream.
enum : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2, kInner = 3 };

/// A hull cell: its node, its first voxel (relative to the cube's corner) and its edge in voxels.
struct Cell {
  const OctreeNode* node;
  Eigen::Vector3i min_voxel;
  int edge;
};

Cell childCell(const Cell& cell, int c) {
  const int half = cell.edge / 2;
  return {&cell.node->children[c],
          cell.min_voxel + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1) * half, half};
}

inline bool overlapsCube(const Eigen::Vector3i& min_voxel, int edge, const Cell& cell) {
  for (int a = 0; a < 3; ++a) {
    if (min_voxel[a] >= cell.min_voxel[a] + cell.edge || cell.min_voxel[a] >= min_voxel[a] + edge) {
      return false;
    }
  }
  return true;
}

inline bool insideCell(const Eigen::Vector3i& min_voxel, int edge, const Cell& cell) {
  for (int a = 0; a < 3; ++a) {
    if (min_voxel[a] < cell.min_voxel[a] || min_voxel[a] + edge > cell.min_voxel[a] + cell.edge) {
      return false;
    }
  }
  return true;
}

/// The state of the voxels [min_voxel, min_voxel + edge)^3 below `cell` that holds them all:
/// kFree (out cells), kOccupied (in and surface cells), or kInner when they differ. `found` is
/// the state met so far (kUnknown: none yet).
uint8_t stateOver(const Cell& cell, const Eigen::Vector3i& min_voxel, int edge, uint8_t found) {
  if (!cell.node->children) {
    const uint8_t state = cell.node->state == CellState::kOut ? kFree : kOccupied;
    return found == kUnknown || found == state ? state : kInner;
  }
  // The children the voxels reach: per axis the lower half, the upper half or both.
  const int half = cell.edge / 2;
  int low[3], high[3];
  for (int a = 0; a < 3; ++a) {
    const int middle = cell.min_voxel[a] + half;
    low[a] = min_voxel[a] >= middle ? 1 : 0;
    high[a] = min_voxel[a] + edge > middle ? 1 : 0;
  }
  for (int z = low[2]; z <= high[2]; ++z) {
    for (int y = low[1]; y <= high[1]; ++y) {
      for (int x = low[0]; x <= high[0]; ++x) {
        found = stateOver(childCell(cell, x | (y << 1) | (z << 2)), min_voxel, edge, found);
        if (found == kInner) return kInner;
      }
    }
  }
  return found;
}

/// The least cell below `cell` (which holds them) that holds the voxels
/// [min_voxel, min_voxel + edge)^3.
Cell holdingCell(Cell cell, const Eigen::Vector3i& min_voxel, int edge) {
  while (cell.node->children && edge <= cell.edge / 2) {
    const int half = cell.edge / 2;
    int c = 0;
    for (int a = 0; a < 3; ++a) {
      const int middle = cell.min_voxel[a] + half;
      if (min_voxel[a] >= middle) {
        c |= 1 << a;
      } else if (min_voxel[a] + edge > middle) {
        return cell;  // the voxels span both halves on this axis
      }
    }
    cell = childCell(cell, c);
  }
  return cell;
}

class OctomapWriter {
 public:
  OctomapWriter(const VisualHull& hull, CompactOctomap* map)
      : root_{&hull.rootNode(), Eigen::Vector3i::Zero(), 1 << hull.cube().depth},
        origin_key_(hull.cube().origin_voxels + Eigen::Vector3i::Constant(kKeyOffset)),
        map_(map) {
    toKeys({hull.cube().origin_voxels, root_.edge});  // throws beyond OctoMap's key range
  }

  /// OccupancyOcTreeBase::writeBinaryNode from OctoMap's root.
  void write() { writeNode(0, Eigen::Vector3i::Zero(), root_); }

 private:
  /// The code of the OctoMap node at `level` whose first key is `min_key`: unknown beyond the
  /// cube, inner where it holds unknown and known voxels or two states, else the voxels' state.
  uint8_t code(int level, const Eigen::Vector3i& min_key, const Cell& holder) const {
    const int edge = 1 << (kKeyDepth - level);
    const Eigen::Vector3i min_voxel = min_key - origin_key_;
    if (!overlapsCube(min_voxel, edge, root_)) return kUnknown;
    if (!insideCell(min_voxel, edge, root_)) return kInner;
    return stateOver(holdingCell(holder, min_voxel, edge), min_voxel, edge, kUnknown);
  }

  void writeNode(int level, const Eigen::Vector3i& min_key, const Cell& holder) {
    const int edge = 1 << (kKeyDepth - level);
    Cell child_holder = holder;
    const Eigen::Vector3i min_voxel = min_key - origin_key_;
    if (insideCell(min_voxel, edge, root_)) child_holder = holdingCell(holder, min_voxel, edge);
    uint8_t codes[8];
    uint8_t halves[2] = {0, 0};
    for (unsigned int c = 0; c < 8; ++c) {
      codes[c] = code(level + 1, childKey(min_key, edge, c), child_holder);
      // kInner sets bits 2c and 2c + 1, kOccupied bit 2c + 1, kFree bit 2c (writeBinaryNode).
      const unsigned int bits = codes[c] == kInner ? 3u : codes[c] == kOccupied ? 2u : codes[c];
      halves[c / 4] |= static_cast<uint8_t>(bits << (2 * (c % 4)));
    }
    map_->binary_data.push_back(static_cast<char>(halves[0]));
    map_->binary_data.push_back(static_cast<char>(halves[1]));
    for (unsigned int c = 0; c < 8; ++c) {
      const Eigen::Vector3i child_key = childKey(min_key, edge, c);
      if (codes[c] == kInner) writeNode(level + 1, child_key, child_holder);
      if (codes[c] == kOccupied) addCentre(level + 1, child_key);
    }
  }

  /// OcTreeBaseImpl::keyToCoord of an occupied leaf's key at its depth.
  void addCentre(int level, const Eigen::Vector3i& min_key) {
    const int edge = 1 << (kKeyDepth - level);
    const double resolution_m = map_->resolution_m;
    const Eigen::Vector3d offset = (min_key.array() - kKeyOffset).cast<double>();
    Eigen::Vector3d centre;
    if (edge == 1) {
      centre = (offset.array() + 0.5) * resolution_m;
    } else {
      centre = (offset.array() / edge + 0.5) * (resolution_m * edge);
    }
    map_->occupied_centres_W.push_back(centre);
  }

  const Cell root_;
  const Eigen::Vector3i origin_key_;  ///< the key of the cube's first voxel
  CompactOctomap* map_;
};

}  // namespace

CompactOctomap compactOctomap(const VisualHull& hull) {
  CompactOctomap map;
  map.resolution_m = hull.cube().resolution_m;
  OctomapWriter(hull, &map).write();
  return map;
}

}  // namespace sift_hull
