// The hull's OctoMap as toOctomap builds and prunes it, in an array of nodes of its own: its
// binary stream and its occupied leaves, without allocating OctoMap's nodes one by one.

#include <cstdint>
#include <string>
#include <vector>

#include "hull/octomap_keys.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace {

using namespace octomap_keys;

enum : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

/// A node: a leaf of `state`, or (children != 0) inner with its 8 children at children .. + 7,
/// a child of kUnknown without children being one OctoMap does not have.
struct Node {
  uint32_t children = 0;
  uint8_t state = kUnknown;
};

class CompactTree {
 public:
  CompactTree() {
    nodes_.resize(1);
    path_[0] = {0, Eigen::Vector3i::Zero()};
  }

  /// BlockOcTree::insertBlock: the largest aligned nodes inside the block take `state`. The path
  /// down to the least node holding the whole block is read off the keys' bits, starting where
  /// the previous block's path still holds this one (blocks come in the hull's octree order).
  void insertBlock(const KeyBox& block, uint8_t state) {
    const Eigen::Vector3i last = block.end_key - Eigen::Vector3i::Ones();
    int level = 0;
    while (level < path_levels_ && holds(path_[level + 1].min_key, level + 1, block.min_key) &&
           holds(path_[level + 1].min_key, level + 1, last)) {
      ++level;
    }
    const int block_edge = block.end_key.x() - block.min_key.x();
    for (; level < kKeyDepth; ++level) {
      const int edge = 1 << (kKeyDepth - level);
      if (edge <= block_edge) break;  // the block's own level (or above it when misaligned)
      const int bit = kKeyDepth - 1 - level;
      const Eigen::Vector3i low(block.min_key.x() >> bit, block.min_key.y() >> bit,
                                block.min_key.z() >> bit);
      if (low != Eigen::Vector3i(last.x() >> bit, last.y() >> bit, last.z() >> bit)) {
        break;  // the block spans two children here
      }
      const unsigned int c = (low.x() & 1) | ((low.y() & 1) << 1) | ((low.z() & 1) << 2);
      path_[level + 1] = {child(path_[level].node, c), childKey(path_[level].min_key, edge, c)};
    }
    path_levels_ = level;
    insert(path_[level].node, level, path_[level].min_key, block, state);
  }
  /// OcTree::prune: inner nodes whose 8 children are leaves of one known state become that leaf
  /// (bottom up; never the root).
  void prune() {
    if (nodes_[0].children != 0) {
      for (unsigned int c = 0; c < 8; ++c) pruneNode(nodes_[0].children + c);
    }
  }

  /// OccupancyOcTreeBase::writeBinaryNode from the root.
  std::string binaryData() const {
    std::string bytes;
    bytes.reserve(2 * nodes_.size() / 8 + 2);
    appendBinary(0, &bytes);
    return bytes;
  }

  /// The centres of the occupied leaves, as OctoMap's leaf iterator gives them.
  void occupiedCentres(double resolution_m, std::vector<Eigen::Vector3d>* centres) const {
    collectOccupied(0, 0, {0, 0, 0}, resolution_m, centres);
  }

 private:
  /// A node on the last block's path: its index and its first key.
  struct PathNode {
    uint32_t node = 0;
    Eigen::Vector3i min_key = Eigen::Vector3i::Zero();
  };

  /// Whether the node at `level` whose first key is `min_key` holds `key`.
  static bool holds(const Eigen::Vector3i& min_key, int level, const Eigen::Vector3i& key) {
    const int shift = kKeyDepth - level;
    return (min_key.x() >> shift) == (key.x() >> shift) &&
           (min_key.y() >> shift) == (key.y() >> shift) &&
           (min_key.z() >> shift) == (key.z() >> shift);
  }

  bool isLeaf(uint32_t node) const { return nodes_[node].children == 0; }
  bool exists(uint32_t node) const { return !isLeaf(node) || nodes_[node].state != kUnknown; }

  uint32_t child(uint32_t node, unsigned int c) {
    if (nodes_[node].children == 0) {
      const uint32_t first = static_cast<uint32_t>(nodes_.size());
      nodes_.resize(nodes_.size() + 8);
      nodes_[node].children = first;
    }
    return nodes_[node].children + c;
  }

  void insert(uint32_t node, int level, const Eigen::Vector3i& min_key, const KeyBox& block,
              uint8_t state) {
    const int edge = 1 << (kKeyDepth - level);
    if (within(min_key, edge, block)) {
      nodes_[node].children = 0;
      nodes_[node].state = state;
      return;
    }
    for (unsigned int c = 0; c < 8; ++c) {
      const Eigen::Vector3i child_key = childKey(min_key, edge, c);
      if (!overlaps(child_key, edge / 2, block)) continue;
      const uint32_t next = child(node, c);  // may move nodes_: no reference kept across it
      insert(next, level + 1, child_key, block, state);
    }
  }

  void pruneNode(uint32_t node) {
    if (isLeaf(node)) return;
    const uint32_t first = nodes_[node].children;
    for (unsigned int c = 0; c < 8; ++c) pruneNode(first + c);
    const uint8_t state = nodes_[first].state;
    if (state == kUnknown) return;
    for (unsigned int c = 0; c < 8; ++c) {
      if (!isLeaf(first + c) || nodes_[first + c].state != state) return;
    }
    nodes_[node].children = 0;
    nodes_[node].state = state;
  }

  void appendBinary(uint32_t node, std::string* bytes) const {
    const uint32_t first = nodes_[node].children;
    uint8_t halves[2] = {0, 0};
    for (unsigned int c = 0; first != 0 && c < 8; ++c) {
      const uint32_t next = first + c;
      if (!exists(next)) continue;
      // As writeOctomapBinaryData: 3 inner, 2 occupied, 1 free, at bits 2c and 2c + 1.
      const unsigned int code = !isLeaf(next) ? 3u : (nodes_[next].state == kOccupied ? 2u : 1u);
      halves[c / 4] |= static_cast<uint8_t>(code << (2 * (c % 4)));
    }
    bytes->push_back(static_cast<char>(halves[0]));
    bytes->push_back(static_cast<char>(halves[1]));
    for (unsigned int c = 0; first != 0 && c < 8; ++c) {
      if (!isLeaf(first + c)) appendBinary(first + c, bytes);
    }
  }

  void collectOccupied(uint32_t node, int level, const Eigen::Vector3i& min_key,
                       double resolution_m, std::vector<Eigen::Vector3d>* centres) const {
    const int edge = 1 << (kKeyDepth - level);
    if (isLeaf(node)) {
      if (nodes_[node].state != kOccupied) return;
      // OcTreeBaseImpl::keyToCoord of the node's key at its depth.
      const Eigen::Vector3d offset = (min_key.array() - kKeyOffset).cast<double>();
      Eigen::Vector3d centre;
      if (edge == 1) {
        centre = (offset.array() + 0.5) * resolution_m;
      } else {
        centre = (offset.array() / edge + 0.5) * (resolution_m * edge);
      }
      centres->push_back(centre);
      return;
    }
    for (unsigned int c = 0; c < 8; ++c) {
      collectOccupied(nodes_[node].children + c, level + 1, childKey(min_key, edge, c),
                      resolution_m, centres);
    }
  }

  std::vector<Node> nodes_;
  PathNode path_[kKeyDepth + 1];
  int path_levels_ = 0;  ///< levels of path_ below the root that are valid
};

}  // namespace

CompactOctomap compactOctomap(const VisualHull& hull) {
  CompactTree tree;
  for (const VoxelBlock& block : occupiedBlocks(hull)) tree.insertBlock(toKeys(block), kOccupied);
  for (const VoxelBlock& block : carvedBlocks(hull)) tree.insertBlock(toKeys(block), kFree);
  tree.prune();
  CompactOctomap map;
  map.resolution_m = hull.cube().resolution_m;
  map.binary_data = tree.binaryData();
  tree.occupiedCentres(map.resolution_m, &map.occupied_centres_W);
  return map;
}

}  // namespace sift_hull
