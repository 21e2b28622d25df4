#pragma once

// OctoMap's key space for the hull's maps (toOctomap, compactOctomap): voxels of the hull's
// resolution, keys 2^15 around the world origin's voxel, blocks of the hull's cells in keys.

#include <Eigen/Core>
#include <stdexcept>
#include <vector>

#include "sift_hull/hull/octree.h"

namespace sift_hull {
namespace octomap_keys {

constexpr int kKeyDepth = 16;
constexpr int kKeyOffset = 1 << (kKeyDepth - 1);  // OctoMap's key of the world origin's voxel

/// OctoMap keys [min_key, end_key) on each axis.
struct KeyBox {
  Eigen::Vector3i min_key;
  Eigen::Vector3i end_key;
};

inline bool overlaps(const Eigen::Vector3i& min_key, int edge, const KeyBox& box) {
  return ((min_key.array() < box.end_key.array()) &&
          (box.min_key.array() < (min_key.array() + edge)))
      .all();
}

inline bool within(const Eigen::Vector3i& min_key, int edge, const KeyBox& box) {
  return ((min_key.array() >= box.min_key.array()) &&
          (min_key.array() + edge <= box.end_key.array()))
      .all();
}

inline Eigen::Vector3i childKey(const Eigen::Vector3i& min_key, int edge, unsigned int c) {
  return min_key + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1) * (edge / 2);
}

inline KeyBox toKeys(const VoxelBlock& block) {
  const Eigen::Vector3i min_key = block.min_voxels + Eigen::Vector3i::Constant(kKeyOffset);
  const KeyBox keys{min_key, min_key + Eigen::Vector3i::Constant(block.edge_voxels)};
  if ((keys.min_key.array() < 0).any() || (keys.end_key.array() > 2 * kKeyOffset).any()) {
    throw std::out_of_range(
        "the hull lies beyond OctoMap's key range (2^16 voxels around the world origin) at this "
        "resolution");
  }
  return keys;
}

}  // namespace octomap_keys
}  // namespace sift_hull
