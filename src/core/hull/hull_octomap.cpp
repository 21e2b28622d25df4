#include "sift_hull/hull/hull_octomap.h"

#include <octomap/OcTree.h>

#include <fstream>
#include <ostream>
#include <stdexcept>

namespace sift_hull {
namespace {

constexpr int kKeyDepth = 16;
constexpr int kKeyOffset = 1 << (kKeyDepth - 1);  // OctoMap's key of the world origin's voxel

struct KeyBlock {
  Eigen::Vector3i min_key;
  int edge;
};

bool overlaps(const Eigen::Vector3i& min_key, int edge, const KeyBlock& block) {
  return ((min_key.array() < (block.min_key.array() + block.edge)) &&
          (block.min_key.array() < (min_key.array() + edge)))
      .all();
}

bool within(const Eigen::Vector3i& min_key, int edge, const KeyBlock& block) {
  return ((min_key.array() >= block.min_key.array()) &&
          (min_key.array() + edge <= block.min_key.array() + block.edge))
      .all();
}

/// An OcTree that takes whole blocks of voxels, setting the largest aligned nodes inside a block
/// at once instead of every voxel.
class BlockOcTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  void insertOccupied(const KeyBlock& block) {
    if (root == nullptr) {
      root = new octomap::OcTreeNode();
      ++tree_size;
    }
    if (isAligned(block)) return insertAligned(block);
    insert(root, 0, Eigen::Vector3i::Zero(), block);
  }

 private:
  static bool isAligned(const KeyBlock& block) {
    const Eigen::Vector3i& key = block.min_key;
    return key.x() % block.edge == 0 && key.y() % block.edge == 0 && key.z() % block.edge == 0;
  }

  /// A block that is one octree node (most of them: the hull's cells are octree cells): the path
  /// to it is read off its key bits, with no overlap tests.
  void insertAligned(const KeyBlock& block) {
    octomap::OcTreeNode* node = root;
    for (int level = 0; (1 << (kKeyDepth - level)) > block.edge; ++level) {
      const int bit = kKeyDepth - 1 - level;
      const unsigned int c = ((block.min_key.x() >> bit) & 1) |
                             (((block.min_key.y() >> bit) & 1) << 1) |
                             (((block.min_key.z() >> bit) & 1) << 2);
      node = nodeChildExists(node, c) ? getNodeChild(node, c) : createNodeChild(node, c);
    }
    makeOccupiedLeaf(node);
  }

  void insert(octomap::OcTreeNode* node, int level, const Eigen::Vector3i& min_key,
              const KeyBlock& block) {
    const int edge = 1 << (kKeyDepth - level);
    if (within(min_key, edge, block)) return makeOccupiedLeaf(node);
    for (unsigned int c = 0; c < 8; ++c) {
      const Eigen::Vector3i child_key =
          min_key + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1) * (edge / 2);
      if (!overlaps(child_key, edge / 2, block)) continue;
      octomap::OcTreeNode* child =
          nodeChildExists(node, c) ? getNodeChild(node, c) : createNodeChild(node, c);
      insert(child, level + 1, child_key, block);
    }
  }

  void makeOccupiedLeaf(octomap::OcTreeNode* node) {
    for (unsigned int c = 0; c < 8; ++c) {
      if (nodeChildExists(node, c)) deleteNodeChild(node, c);
    }
    node->setLogOdds(getClampingThresMaxLog());
  }
};

KeyBlock toKeys(const VoxelBlock& block) {
  const KeyBlock keys{block.min_voxels + Eigen::Vector3i::Constant(kKeyOffset), block.edge_voxels};
  if ((keys.min_key.array() < 0).any() ||
      (keys.min_key.array() + keys.edge > 2 * kKeyOffset).any()) {
    throw std::out_of_range(
        "the hull lies beyond OctoMap's key range (2^16 voxels around the world origin) at this "
        "resolution");
  }
  return keys;
}

}  // namespace

std::unique_ptr<octomap::OcTree> toOctomap(const VisualHull& hull) {
  auto tree = std::make_unique<BlockOcTree>(hull.cube().resolution_m);
  for (const VoxelBlock& block : occupiedBlocks(hull)) tree->insertOccupied(toKeys(block));
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

void writeOctomapBinaryData(const octomap::OcTree& tree, std::ostream& out) {
  if (tree.getRoot() != nullptr) tree.writeBinaryNode(out, tree.getRoot());
}

void writeOctomap(const octomap::OcTree& tree, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  // AbstractOccupancyOcTree::writeBinaryConst's header; the first line is what readers check.
  out << "# Octomap OcTree binary file\n"
      << "# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
      << "id " << tree.getTreeType() << "\nsize " << tree.size() << "\nres " << tree.getResolution()
      << "\ndata\n";
  writeOctomapBinaryData(tree, out);
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write the octree");
}

}  // namespace sift_hull
